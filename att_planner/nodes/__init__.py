"""The flight-side ROS nodes (thin adapters over ROS-free cores) and the suite's rclpy client."""

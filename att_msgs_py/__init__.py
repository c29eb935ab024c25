"""Wire format: the att_msgs interfaces and the one module that converts them to numpy."""

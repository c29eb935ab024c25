"""Flight side: maneuver planners, controllers and offline tools."""

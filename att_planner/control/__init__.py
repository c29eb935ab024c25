"""Control laws (:mod:`.tracking`, :mod:`.magnetorquer`) and the controller core (:mod:`.controller`), no ROS."""

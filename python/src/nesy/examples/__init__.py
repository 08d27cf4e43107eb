"""Example robot servers built on ``nesy.robot.RobotServer``.

- ``logging_robot``: ``LoggingRobot``, a stand-in robot that moves nothing, answers perception
  from a fixed table of objects (or a scene file) and logs every call it receives.
- ``sim_proxy_robot``: ``SimulatedArm``, an adapter whose "robot" is nesy's own simulator
  (``nesy robot-server``), reached through ``nesy.robot.RobotClient``: the shape of a real
  adapter, runnable without hardware.
- ``franky_sketch`` and ``ros2_sketch``: untested sketches of adapters for a Franka arm
  (franky) and for a ROS 2 robot (action clients).

Run the first two as modules, e.g. ``python3 -m nesy.examples.logging_robot --help``.
"""

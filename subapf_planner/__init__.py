"""subapf_planner: local planner with a subharmonic artificial potential field.

Implements Peng, Zhang and Xiong, "Smooth Path Planning with Subharmonic
Artificial Potential Field", with the corrections of README "Where the paper is
wrong". The core modules (config, potentials, apf, sampling, scan, command,
dwa, planner) are pure numpy and never import rclpy.
"""

__version__ = '0.1.0'

"""subapf_planner: local planner with a subharmonic artificial potential field.

Implements Peng, Zhang and Xiong, "Smooth Path Planning with Subharmonic
Artificial Potential Field", with the corrections of docs/design.md "Where the paper is
wrong". Subpackages (test/test_layers.py enforces who imports whom):

* ``core``: pure numpy/scipy, no ROS: params, config, robot (the robot and its
  frames), status, scan, potentials, apf, sampling, command, dwa, occupancy,
  navigation, memory, planner (perceive, gate, plan), loop (the decision loop);
* ``sim``: the PyBullet burger, world files and suites, episodes;
* ``bag``: MCAP recording and reading;
* ``ros``: nodes, message conversions, input checks, replays;
* ``tools``: the command-line programs.
"""

__version__ = '0.1.0'

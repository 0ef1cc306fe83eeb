"""The hand-written MuJoCo loop ``bench/engine_bench.py`` times ``drive --engine mujoco``
against: the simplecar's export (``urdfkit export mjcf car.urdf --ground --actuators
velocity``), loaded by MuJoCo itself, stepped ``N`` times with every wheel at 10 rad/s (velocity
actuators, the file's force range) and the hinges held, at drive's time step and gravity.

Usage: python mujoco_loop.py car.xml N
"""

import sys

import mujoco

model = mujoco.MjModel.from_xml_path(sys.argv[1])
data = mujoco.MjData(model)
model.opt.timestep = 1 / 240
model.opt.gravity[:] = (0.0, 0.0, -10.0)
# actuators in joint order: left hinge, left front wheel, right hinge, right front wheel,
# left back wheel, right back wheel (the export's)
data.ctrl[:] = [0.0, 10.0, 0.0, 10.0, 10.0, 10.0]
for _ in range(int(sys.argv[2])):
    mujoco.mj_step(model, data)
# the car moved: a baseline that did nothing would not print this
assert data.qpos[0] > 1.0, data.qpos[:3]
print(data.qpos[:3])

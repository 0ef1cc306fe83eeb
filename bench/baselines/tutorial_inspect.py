import sys, pybullet as p  # noqa: E401, I001  (the tutorial's own six lines, kept as written)
p.connect(p.DIRECT)
robot = p.loadURDF(sys.argv[1])
for i in range(p.getNumJoints(robot)):
    print(p.getJointInfo(robot, i))
p.disconnect()

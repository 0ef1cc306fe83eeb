"""Other engines' formats: the MJCF writer, its agreement with PyBullet, exact kinematics."""

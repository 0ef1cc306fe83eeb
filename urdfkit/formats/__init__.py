"""Robots written for other engines: the URDF as PyBullet reads it, exact kinematics, MJCF."""

"""Baseline for bench/render_bench.py: the shortest script that renders a URDF to a PNG.

What a PyBullet user writes by hand: DIRECT, loadURDF, one getCameraImage with the
TinyRenderer from a fixed camera, Pillow to save. No framing, no grid, no supersampling, no
checks, so it is the floor that ``urdfkit render`` is measured against.

Usage: python tutorial_render.py ROBOT.urdf OUT.png
"""

import sys

import numpy as np
import pybullet as p
from PIL import Image

p.connect(p.DIRECT)
body = p.loadURDF(sys.argv[1], useFixedBase=True)
view = p.computeViewMatrixFromYawPitchRoll([0, 0, 0], 1.5, 45, -30, 0, 2)
proj = p.computeProjectionMatrixFOV(30, 800 / 600, 0.01, 100)
w, h, rgba, _, _ = p.getCameraImage(800, 600, view, proj, renderer=p.ER_TINY_RENDERER)
Image.fromarray(np.reshape(np.asarray(rgba, dtype=np.uint8), (h, w, 4))[:, :, :3]).save(
    sys.argv[2])
p.disconnect()

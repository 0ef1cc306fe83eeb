"""One engine against another: PyBullet's loaded inertia, and agree's row-by-row proof."""

"""The floor for a cold `urdfkit check`: parse every URDF and read every mesh it names, with the
fastest plain reader for each format, computing nothing (issue 30).

check must read what a file names to judge its inertia, units and shape; this program pays
exactly that and no more: the walk, lxml's parse of each .urdf/.xacro, and for each distinct
mesh a read into numbers: numpy for binary STL, a split into floats for OBJ and ASCII STL,
lxml plus float arrays for COLLADA. Relative paths resolve beside the file, and ``package://``
(and ``package:///``) by searching the file's folder and five above, as PyBullet does.

Usage: python bench/baselines/floor.py FOLDER   (prints: files, meshes, floats read)
"""

import os
import sys

import numpy as np
from lxml import etree

parser = etree.XMLParser(resolve_entities=False, no_network=True)
seen: set[str] = set()
files = floats = 0


def locate(name: str, base: str) -> str | None:
    if name.startswith("package://"):
        rest = name[len("package://"):].split("/", 1)[-1]
        folder = base
        for _ in range(6):
            for candidate in (os.path.join(folder, rest), os.path.join(folder, name[10:])):
                if os.path.isfile(candidate):
                    return candidate
            folder = os.path.dirname(folder)
        return None
    path = name if os.path.isabs(name) else os.path.join(base, name)
    return path if os.path.isfile(path) else None


def read_mesh(path: str) -> int:
    low = path.lower()
    if low.endswith(".stl"):
        with open(path, "rb") as f:
            head = f.read(84)
            if len(head) == 84:
                n = int.from_bytes(head[80:84], "little")
                if 84 + 50 * n == os.fstat(f.fileno()).st_size:
                    rec = np.fromfile(f, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", 9),
                                                         ("a", "<u2")]), count=n)
                    return rec["v"].size
            text = head + f.read()
        return len([float(x) for line in text.split(b"\n") if line.strip().startswith(b"vertex")
                    for x in line.split()[1:4]])
    if low.endswith(".obj"):
        with open(path, "rb") as f:
            data = f.read()
        values = [x for line in data.split(b"\n") if line.startswith(b"v ")
                  for x in line.split()[1:4]]
        return np.array(values, dtype=np.float64).size
    if low.endswith(".dae"):
        tree = etree.parse(path, parser)
        total = 0
        for el in tree.iter("{*}float_array"):
            total += np.array((el.text or "").split(), dtype=np.float64).size
        return total
    return 0


for folder, _, names in os.walk(sys.argv[1]):
    for name in sorted(names):
        if not name.endswith((".urdf", ".xacro")):
            continue
        path = os.path.join(folder, name)
        files += 1
        try:
            root = etree.parse(path, parser).getroot()
        except etree.XMLSyntaxError:
            continue
        for mesh in root.iter("mesh"):
            target = locate(mesh.get("filename") or "", folder)
            if target is None or target in seen:
                continue
            seen.add(target)
            try:
                floats += read_mesh(target)
            except (OSError, ValueError, etree.XMLSyntaxError):
                pass
print(files, len(seen), floats)

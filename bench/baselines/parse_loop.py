"""Baseline for `urdfkit check`: walk a folder and parse every .urdf/.xacro with lxml, nothing
else (the floor any validator pays: start-up, the walk, the XML parse).

Usage: python bench/baselines/parse_loop.py FOLDER
"""

import os
import sys

from lxml import etree

parser = etree.XMLParser(resolve_entities=False, no_network=True)
count = 0
for folder, _, names in os.walk(sys.argv[1]):
    for name in names:
        if name.endswith((".urdf", ".xacro")):
            try:
                etree.parse(os.path.join(folder, name), parser)
            except etree.XMLSyntaxError:
                pass
            count += 1
print(count)

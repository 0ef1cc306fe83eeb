"""The agreement table of docs/export.md: export + agree on each robot, and MuJoCo's own loader.

Usage (robots as `urdfkit` takes them, extra options after `--`)::

    python bench/export_agreement.py r2d2.urdf kuka_iiwa/model.urdf -- --package-path DIR

For each robot: ``urdfkit export mjcf`` into a temp folder, ``urdfkit agree --json`` on it,
and the same agree on what MuJoCo's own URDF reader makes of the file
(``mujoco.MjModel.from_xml_path`` then ``mj_saveLastXML``), when it reads it at all.
Prints one markdown row per robot and model: the worst figure of each row group.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path


def _agree(robot: str, model: str, extra: list[str]) -> dict:
    r = subprocess.run([sys.executable, "-m", "urdfkit", "agree", robot, model, "--json", *extra],
                       capture_output=True, text=True)
    if r.returncode == 2:
        return {"error": r.stderr.strip().splitlines()[-1]}
    return json.loads(r.stdout)


def _row(name: str, data: dict) -> str:
    if "error" in data:
        return f"| {name} | refused: {data['error'][:120]} |"
    rows = {r["check"]: r for r in data["rows"]}
    failing = [r["check"] for r in data["rows"] if r["status"] == "fail"]

    def fig(key: str) -> str:
        r = next((v for k, v in rows.items() if k.startswith(key)), None)
        if r is None or r["value"] is None:
            return "-"
        return f"{r['value']:.2g}"

    swing = next((k for k in rows if k.startswith("free swing")), "free swing -")
    return (f"| {name} | {'all pass' if not failing else 'FAIL: ' + ', '.join(failing)} | "
            f"{fig('inertia tensors')} | {fig('frames vs PyBullet: position')} | "
            f"{fig('frames vs exact FK: position')} | {fig('mass matrix')} | "
            f"{fig('inverse dynamics')} | {fig('free swing')} ({swing.split()[2]} s) |")


def main(argv: list[str]) -> None:
    robots, extra = (argv[: argv.index("--")], argv[argv.index("--") + 1:]) if "--" in argv \
        else (argv, [])
    print("| robot / model | agree | inertia (rel) | frames vs PyBullet (m) | frames vs FK (m) "
          "| mass matrix (rel) | inverse dynamics (rel) | swing (rad) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        for k, robot in enumerate(robots):
            out = Path(tmp) / f"{k}_{Path(robot).name.split('.')[0]}.xml"
            r = subprocess.run([sys.executable, "-m", "urdfkit", "export", "mjcf", robot,
                                "-o", str(out), *extra], capture_output=True, text=True)
            if r.returncode != 0:
                print(f"| {robot} (export) | refused: {r.stderr.strip().splitlines()[-1][:160]} |")
            else:
                print(_row(f"{robot} (export)", _agree(robot, str(out), extra)))
            print(_row(f"{robot} (MuJoCo's loader)", _mujoco_loader(robot, Path(tmp), extra)))


def _mujoco_loader(robot: str, tmp: Path, extra: list[str]) -> dict:
    import mujoco

    from urdfkit.sources.resolve import locate

    path = locate(robot)
    try:
        m = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as e:
        return {"error": "MuJoCo: " + str(e).strip().splitlines()[0]}
    saved = tmp / f"{abs(hash(str(path)))}_mujoco.xml"
    mujoco.mj_saveLastXML(str(saved), m)
    from lxml import etree

    doc = etree.parse(str(saved))  # its mesh names are relative to the URDF's folder
    compiler = doc.find("compiler")
    if compiler is None:
        compiler = etree.SubElement(doc.getroot(), "compiler")
        doc.getroot().insert(0, compiler)
    compiler.set("meshdir", str(path.parent))
    doc.write(str(saved))
    return _agree(robot, str(saved), extra)


if __name__ == "__main__":
    main(sys.argv[1:])

"""A bare two-command typer app doing the same PyBullet work as `urdfkit joints --json`.

No guard, no quiet stdout, no xacro/package handling: the floor for a typer CLI over PyBullet.
"""

import json
import sys

import typer

app = typer.Typer(add_completion=False)
TYPES = {0: "REVOLUTE", 1: "PRISMATIC", 2: "SPHERICAL", 3: "PLANAR", 4: "FIXED"}


@app.command()
def joints(file: str, as_json: bool = typer.Option(False, "--json")) -> None:
    """Print getJointInfo for every joint."""
    import pybullet as p

    p.connect(p.DIRECT)
    robot = p.loadURDF(file)
    rows = []
    for i in range(p.getNumJoints(robot)):
        info = p.getJointInfo(robot, i)
        rows.append({"jointIndex": info[0], "jointName": info[1].decode(),
                     "jointType": TYPES[info[2]], "linkName": info[12].decode(),
                     "jointAxis": list(info[13]), "parentIndex": info[16]})
    p.disconnect()
    sys.stdout.write(json.dumps({"file": file, "joints": rows}, indent=2) + "\n")


@app.command()
def info(file: str) -> None:
    """Print the joint count."""
    import pybullet as p

    p.connect(p.DIRECT)
    robot = p.loadURDF(file)
    print(p.getNumJoints(robot))
    p.disconnect()


if __name__ == "__main__":
    app()

"""export, agree: a URDF written for MuJoCo (formats/), and proof that it agrees (exchange/)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

if TYPE_CHECKING:
    from urdfkit.formats.mjcf import Export

from urdfkit.commands import present as show
from urdfkit.commands.shared import (
    AllOpt,
    ArgOpt,
    FileArg,
    ForceOpt,
    JsonOpt,
    NoGuardOpt,
    PackageOpt,
    PackagePathOpt,
    command,
    examples,
    open_input_and_warn,
)

FixedBaseOpt = Annotated[bool, typer.Option(
    "--fixed-base", help="Weld the root link to the world, as loadURDF's useFixedBase "
    "(default: a free joint, as loadURDF; a root of mass 0 is welded, as PyBullet fixes it).")]
ShapesOpt = Annotated[bool, typer.Option(
    "--inertia-from-shapes", help="Mirror PyBullet's load without URDF_USE_INERTIA_FROM_FILE: "
    "inertia recomputed from the collision shapes (default: the file's, with the flag).")]
SelfCollisionOpt = Annotated[bool, typer.Option(
    "--self-collision", help="Let the robot's links collide, as URDF_USE_SELF_COLLISION "
    "(parent-child pairs excluded).")]


def _verify_options(fixed_base: bool, shapes: bool, self_collision: bool, poses: int,
                    seed: int) -> Any:
    from urdfkit.exchange.agree import AgreeOptions

    return AgreeOptions(fixed_base=fixed_base, inertia_from_file=not shapes,
                        self_collision=self_collision, poses=poses, seed=seed)


def _figure(x: float | None) -> str:
    if x is None:
        return "-"
    if x == 0:
        return "0"
    return f"{x:.2g}"


def agreement_dict(a: Any) -> dict[str, Any]:
    """``agree --json``: the rows with their tolerances, what was not matched, ok."""
    return {"file": a.file, "model": a.model, "ok": a.ok, "load_flags": a.load_flags,
            "rows": [{"group": r.group, "check": r.what, "value": r.value,
                      "tolerance": r.tolerance, "unit": r.unit, "status": r.status,
                      "detail": r.detail} for r in a.rows],
            "unmatched_links": a.unmatched_links, "unmatched_joints": a.unmatched_joints,
            "extra_joints": a.extra_joints, "matched_by": a.matched_by, "warnings": a.warnings,
            "engine": a.engine, "indices": a.indices}


def agreement_report(a: Any, show_all: bool = False) -> None:
    """``agree``'s table: one row per comparison, the tolerance beside each figure."""
    rows = [[r.group, r.what, _figure(r.value), _figure(r.tolerance), r.unit,
             {"pass": "ok", "fail": "FAIL"}.get(r.status, r.status), show.tidy(r.detail)]
            for r in a.rows]
    columns: list[show.Column] = [("group", 1, "left"), ("check", 0, "left"),
                                  ("worst", 0, "right"), ("tolerance", 0, "right"),
                                  ("unit", 2, "left"), ("", 0, "left"), ("where", 1, "left")]
    failed = sum(not r.ok for r in a.rows)
    title = (f"{a.file} in PyBullet vs " + (f"{a.model} in " if a.model != a.file else "")
             + f"{a.engine}: "
             + ("every row agrees" if not failed else f"{failed} row(s) disagree"))
    for w in a.warnings:
        show.warn(f"{a.model}: {a.engine}: {w}")
    show.table(title, columns, rows, show_all)
    if a.indices:
        _indices_report(a, show_all)
    if a.unmatched_links:
        show.note(f"{len(a.unmatched_links)} link(s) with no body or site matched: "
                  + ", ".join(a.unmatched_links), stderr=False)
    if a.matched_by:
        show.note(f"{len(a.matched_by)} pair(s) matched by another way than the name: "
                  + ", ".join(f"{p['urdf']} = {p['mjcf']} ({p['how']})" for p in a.matched_by),
                  stderr=False)
    show.note("PyBullet loaded with " + (" | ".join(a.load_flags) or "no flags")
              + ("; its link damping and velocity motors off for the swing"
                 if any(r.group == "swing" for r in a.rows) else ""), stderr=False)


def _indices_report(a: Any, show_all: bool) -> None:
    """Each movable joint's indices in both engines, side by side (``--engine``)."""
    def cell(side: dict[str, Any] | None, *keys: str) -> str:
        if side is None:
            return "-"
        return " ".join(f"{side[k]}" + (f"..{side[k] + side['n' + k] - 1}"
                                         if side.get("n" + k, 1) > 1 else "") for k in keys)

    rows = [[str(r["joint"]), cell(r["pybullet"], "index"), cell(r["pybullet"], "action"),
             cell(r["pybullet"], "q"), cell(r["pybullet"], "u"), cell(r["engine"], "q"),
             cell(r["engine"], "v"), r["engine"]["kind"] if r["engine"] else "-"]
            for r in a.indices]
    columns: list[show.Column] = [("joint", 1, "left"), ("index", 0, "right"),
                                  ("action", 0, "right"), ("q", 0, "right"),
                                  ("u", 0, "right"), (f"{a.engine} q", 0, "right"),
                                  ("v", 0, "right"), ("kind", 1, "left")]
    show.table(f"joint indices: PyBullet (getJointInfo index, action order, qIndex, uIndex) "
               f"and {a.engine} (base welded)", columns, rows, show_all)


def _export_dict(file: str, e: Export, flags: list[str]) -> dict[str, Any]:
    return {"file": file, "written": bool(e.paths), "paths": e.paths, "bodies": e.bodies,
            "sites": e.sites, "repaired": e.repaired, "mirrored_flags": flags,
            "notes": [{"kind": n.kind, "message": n.message, "line": n.line} for n in e.notes]}


class _Verify:
    """``--verify``: agree run on the staged XML before it takes its place (kept for the report).

    A refusal (agree exits 1) leaves nothing of the export behind; MuJoCo refusing the file
    raises agree's InputError, which leaves nothing either (``write_export``).
    """

    def __init__(self, resolved: Any, out: str, options: Any) -> None:
        self.resolved, self.out, self.options = resolved, out, options
        self.agreement: Any = None

    def __call__(self, staged: Path) -> bool:
        from urdfkit.exchange.agree import agree as run_agree

        self.agreement = run_agree(self.resolved, staged, self.options)
        self.agreement.model = self.out  # the file the user named, not the staged one
        return bool(self.agreement.ok)


def _report(name: str, out: str, e: Any, flags: list[str], fixed_base: bool,
            agreement: Any) -> None:
    """The lines of export: its notes, what was written (or that nothing was), agree's table."""
    for n in e.notes:
        where = f"{name}:{n.line}: " if n.line else f"{name}: "
        show.note(f"{where}{n.kind}: {n.message}")
    if e.paths:
        show.wrote(out, f"{len(e.bodies)} bodies, {len(e.sites)} sites, "
                   f"{len(e.paths) - 1} mesh file(s); mirrors loadURDF with "
                   + (" | ".join(flags) or "no flags")
                   + (" and useFixedBase" if fixed_base else ""))
    if agreement is not None:
        agreement_report(agreement)
    if not e.paths:
        show.warn(f"{out}: not written: it disagrees with PyBullet (the rows above); nothing "
                  "of this export was left behind")


@command(examples(
    "urdfkit export mjcf kuka_iiwa/model.urdf -o iiwa.xml",
    "urdfkit export mjcf robot.urdf.xacro -a prefix:=left_ -o robot.xml --actuators position",
    "urdfkit export mjcf simplecar.urdf -o car.xml --ground --actuators velocity --verify",
    "python -m mujoco.viewer --mjcf car.xml"))
def export(
    kind: Annotated[str, typer.Argument(metavar="mjcf", help="The format: mjcf (MuJoCo).")],
    file: FileArg,
    output: Annotated[str | None, typer.Option(
        "--output", "-o", metavar="FILE.xml", help="Where to write; the meshes go to "
        "FILE_assets/ beside it.", show_default="the robot file's name, .xml")] = None,
    fixed_base: FixedBaseOpt = False,
    inertia_from_shapes: ShapesOpt = False,
    self_collision: SelfCollisionOpt = False,
    actuators: Annotated[str, typer.Option(
        "--actuators", metavar="motor|position|velocity|none",
        help="One actuator per movable joint that mimics none: motor (ctrlrange from the "
        "effort limit), position or velocity servos (forcerange from it), or none.")]
    = "motor",
    gain: Annotated[float | None, typer.Option(
        "--gain", help="kp of position servos (N m/rad) or kv of velocity servos (N m s/rad).",
        show_default="100 / 1")] = None,
    ground: Annotated[bool, typer.Option(
        "--ground", help="Add a ground plane and a light, so the file simulates as it is.")]
    = False,
    verify: Annotated[bool, typer.Option(
        "--verify", help="Then run `urdfkit agree` on what was written (exit 1 if it "
        "disagrees).")] = False,
    as_json: JsonOpt = False,
    force: ForceOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Write the robot PyBullet simulates as a standalone MuJoCo model (MJCF + meshes).

    Same joints, limits, damping, masses and full inertia as PyBullet loads with
    URDF_USE_INERTIA_FROM_FILE; fixed links fused into their parent body, each kept as a site
    of its name; meshes copied (COLLADA converted) into FILE_assets/. What is dropped or
    approximated is listed on stderr (or in --json). See docs/export.md.
    """
    from urdfkit.core.errors import ParameterError
    from urdfkit.core.output import check_output
    from urdfkit.formats.mjcf import ExportOptions, asset_dir_for, export_mjcf, write_export
    from urdfkit.formats.mjcf_write import check_asset_dir
    from urdfkit.formats.robot import read_robot

    if kind.lower() != "mjcf":
        raise ParameterError(f"unknown format {kind!r}: export writes mjcf", param="kind")
    out = output or f"{Path(file).name.split('.')[0] or 'robot'}.xml"
    check_output(out, force=force, suffixes=(".xml",), what="the MJCF file")
    check_asset_dir(Path(out).parent / asset_dir_for(out))
    with open_input_and_warn(file, packages=package, xacro_args=arg, guard=not no_guard,
                             package_paths=package_path) as resolved:
        robot = read_robot(resolved.root, resolved.name)
        for w in robot.warnings:
            show.warn(f"{resolved.name}: {w}")
        from urdfkit.exchange.bullet import loaded_inertials, zeroed_repairs

        # what PyBullet simulates: its diagonalised tensors, its defaults, its recomputation
        inertials = loaded_inertials(resolved, inertia_from_file=not inertia_from_shapes)
        # where PyBullet zeroed a tensor, what `urdfkit fix` writes (used where MuJoCo needs it)
        repairs = zeroed_repairs(resolved, robot, inertials) if not inertia_from_shapes else {}
        e = export_mjcf(robot, ExportOptions(
            fixed_base=fixed_base, self_collision=self_collision, actuators=actuators,
            gain=gain, ground=ground, inertials=inertials,
            inertia_from_shapes=inertia_from_shapes, repairs=repairs), asset_dir_for(out))
        # cylinders are written as true cylinders: PyBullet's with URDF_USE_IMPLICIT_CYLINDER
        flags = ["URDF_USE_INERTIA_FROM_FILE"] if not inertia_from_shapes else []
        flags += ["URDF_USE_IMPLICIT_CYLINDER"]
        flags += ["URDF_USE_SELF_COLLISION"] if self_collision else []
        checker = _Verify(resolved, out, _verify_options(
            fixed_base, inertia_from_shapes, self_collision, 100, 0)) if verify else None
        write_export(e, out, force=force, verify=checker)
        agreement = checker.agreement if checker is not None else None
    if as_json:
        data = _export_dict(resolved.name, e, flags)
        data["agreement"] = agreement_dict(agreement) if agreement is not None else None
        show.print_json(data)
    else:
        _report(resolved.name, out, e, flags, fixed_base, agreement)
    raise typer.Exit(0 if e.paths else 1)


@command(examples(
    "urdfkit agree kuka_iiwa/model.urdf iiwa.xml",
    "urdfkit agree panda.urdf mujoco_menagerie/franka_emika_panda/panda.xml --json",
    "urdfkit agree ur5e.urdf --engine pinocchio"))
def agree(
    file: FileArg,
    model: Annotated[str | None, typer.Argument(
        metavar="[MODEL.xml]", help="The MJCF to compare (with --engine mujoco, the "
        "default).")] = None,
    engine: Annotated[str, typer.Option(
        "--engine", metavar="ENGINE", help="mujoco: the MJCF given; mujoco-loader: the URDF "
        "through MuJoCo's own URDF reader; pinocchio, drake: the URDF as that engine loads "
        "it (urdfkit[engines]).")] = "mujoco",
    fixed_base: FixedBaseOpt = False,
    inertia_from_shapes: ShapesOpt = False,
    self_collision: SelfCollisionOpt = False,
    poses: Annotated[int, typer.Option("--poses", min=1, help="Seeded random poses.")] = 100,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the poses.")] = 0,
    name_map: Annotated[list[str] | None, typer.Option(
        "--map", metavar="URDF=MJCF", help="A URDF link or joint and the MJCF body, site or "
        "joint it is, where names differ (repeatable; the rest match by name, then by the "
        "tree's shape).")] = None,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Does another engine's model agree with the URDF PyBullet loads? Both, compared.

    With an MJCF: links are matched to bodies or sites and joints to joints by name;
    structure, link frames at seeded poses, mass matrix, inverse dynamics and a 1 s free
    swing are compared, each with its tolerance. With --engine pinocchio, drake or
    mujoco-loader, the URDF as that engine reads it: joints, each joint's indices in both,
    masses, frames, mass matrix and inverse dynamics. Exit 0: every row holds; 1: rows
    disagree (named); 2: bad input, or the engine refuses the file. Needs urdfkit[mujoco]
    (urdfkit[engines] for --engine). See docs/export.md and docs/engines.md.
    """
    from urdfkit.core.errors import ParameterError
    from urdfkit.exchange.agree import agree as run_agree
    from urdfkit.exchange.agree_engines import AGREE_ENGINES, agree_engine
    from urdfkit.exchange.agree_tree import parse_map

    if engine not in AGREE_ENGINES:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"--engine: no engine named {engine!r}; engines: "
                             f"{', '.join(AGREE_ENGINES)}{hint(engine, AGREE_ENGINES)}",
                             param="engine")
    if (engine == "mujoco") == (model is None):
        raise ParameterError("give an MJCF file (MODEL.xml), or --engine mujoco-loader, "
                             "pinocchio or drake without one", param="MODEL.xml")
    if name_map and engine in ("pinocchio", "drake"):
        raise ParameterError(f"--map: {engine} loads the URDF itself: every name matches",
                             param="map")
    options = _verify_options(fixed_base, inertia_from_shapes, self_collision, poses, seed)
    options.name_map = parse_map(name_map)
    with open_input_and_warn(file, packages=package, xacro_args=arg, guard=not no_guard,
                             package_paths=package_path) as resolved:
        result = run_agree(resolved, model, options) if model is not None else \
            agree_engine(resolved, engine, options)
    if as_json:
        show.print_json(agreement_dict(result))
    else:
        agreement_report(result, show_all)
    raise typer.Exit(0 if result.ok else 1)

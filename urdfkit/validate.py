"""Validation of URDF documents: the rules, and the guard every loader calls.

Rules work on the lxml tree (not on a parsed model) so that every finding can carry the line
it comes from, and so that broken files are described rather than refused at the first error.

:func:`guard` runs the rules that stand between a file and a PyBullet segfault (two roots, a
child with two parents, cycles, duplicate names, ``%`` in names, ...) and raises the first
error as an :class:`~urdfkit.errors.InputError`. Every command that loads a file calls it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass

from lxml import etree

from .errors import InputError

LEVELS = ("info", "warning", "error")

#: PyBullet's state queries fail on bodies with this many links or more (MAX_DEGREE_OF_FREEDOM).
MAX_PYBULLET_LINKS = 128


@dataclass(frozen=True)
class Finding:
    """One problem found in a file.

    Attributes:
        code: A stable identifier such as ``U201``, for ``--select`` and ``--ignore``.
        level: ``error``, ``warning`` or ``info``.
        message: What is wrong with which element, and how to fix it.
        file: The file, as the user named it.
        line: The 1-based line, where known.
    """

    code: str
    level: str
    message: str
    file: str
    line: int | None = None

    def to_dict(self) -> dict[str, object]:
        """The JSON form."""
        return asdict(self)

    def __str__(self) -> str:
        where = self.file if self.line is None else f"{self.file}:{self.line}"
        return f"{where}: {self.level} {self.code}: {self.message}"


class Report:
    """Collects findings for one file."""

    def __init__(self, file: str):
        self.file = file
        self.findings: list[Finding] = []

    def add(self, code: str, level: str, message: str, el: etree._Element | None = None,
            line: int | None = None) -> None:
        if line is None and el is not None:
            line = el.sourceline
        self.findings.append(Finding(code, level, message, self.file, line))

    @property
    def errors(self) -> list[Finding]:
        return [f for f in self.findings if f.level == "error"]


Rule = Callable[[etree._Element, Report], None]


def _elements(root: etree._Element, tag: str) -> Iterator[etree._Element]:
    return (c for c in root if isinstance(c.tag, str) and c.tag == tag)


def _label(el: etree._Element) -> str:
    name = el.get("name")
    return f"<{el.tag} name={name!r}>" if name is not None else f"<{el.tag}>"


# --------------------------------------------------------------------------- structural rules
# These are the rules PyBullet crashes on when they are broken; the guard runs exactly these.


def rule_document(root: etree._Element, r: Report) -> None:
    """U001-U003: root is <robot>, has a name, and has links."""
    if root.tag != "robot":
        r.add("U001", "error", f"root element is <{root.tag}>, expected <robot>", root)
        return
    if not root.get("name"):
        r.add("U002", "error", "<robot> has no name attribute; add name=\"...\"", root)
    if next(_elements(root, "link"), None) is None:
        r.add("U003", "error", "<robot> has no <link>; a robot needs at least one link", root)


def _check_name(el: etree._Element, r: Report) -> str | None:
    name = el.get("name")
    if name is None or not name.strip():
        r.add("U101", "error", f"<{el.tag}> has no name; give it a unique name=\"...\"", el)
        return None
    if "%" in name:
        # PyBullet passes names into printf as the format string: "%s" reads garbage, "%n"
        # writes memory. It crashes the process.
        r.add("U104", "error", f"{_label(el)} contains '%', which crashes PyBullet "
              "(it uses names as printf formats); rename it", el)
    return name


def rule_names(root: etree._Element, r: Report) -> None:
    """U101-U104: links, joints and materials are named, uniquely, without '%'."""
    if root.tag != "robot":
        return
    for tag, code in (("link", "U102"), ("joint", "U103")):
        seen: dict[str, etree._Element] = {}
        for el in _elements(root, tag):
            name = _check_name(el, r)
            if name is None:
                continue
            if name in seen:
                r.add(code, "error", f"duplicate {tag} name {name!r} (first on line "
                      f"{seen[name].sourceline}); names must be unique", el)
            else:
                seen[name] = el
    seen_mat: dict[str, etree._Element] = {}
    for el in _elements(root, "material"):
        name = _check_name(el, r)
        if name is None:
            continue
        if name in seen_mat:
            r.add("U105", "error", f"duplicate material name {name!r} (first on line "
                  f"{seen_mat[name].sourceline})", el)
        seen_mat[name] = el
    for el in root.iter("material"):
        if el.getparent() is not root and el.get("name") and "%" in el.get("name", ""):
            _check_name(el, r)


def rule_tree(root: etree._Element, r: Report) -> None:
    """U201-U207: joints reference links; exactly one root; single parents; no cycles."""
    if root.tag != "robot":
        return
    links = {el.get("name"): el for el in _elements(root, "link") if el.get("name")}
    parent_of: dict[str, tuple[str, etree._Element]] = {}
    children: dict[str, list[str]] = {}
    for j in _elements(root, "joint"):
        jname = j.get("name", "?")
        ends: dict[str, str | None] = {}
        for role in ("parent", "child"):
            sub = j.find(role)
            if sub is None or not sub.get("link"):
                r.add("U201", "error", f"{_label(j)} has no <{role} link=\"...\">", j)
                ends[role] = None
                continue
            link = sub.get("link")
            if link not in links:
                r.add("U202", "error", f"{_label(j)} {role} link {link!r} does not exist; "
                      "declare it with <link name=...>", sub)
                ends[role] = None
            else:
                ends[role] = link
        parent, child = ends.get("parent"), ends.get("child")
        if parent is None or child is None:
            continue
        if parent == child:
            r.add("U203", "error", f"{_label(j)} joins link {parent!r} to itself; parent and "
                  "child must differ", j)
            continue
        if child in parent_of:
            first, first_el = parent_of[child]
            r.add("U204", "error", f"link {child!r} has two parents: joint {first!r} (line "
                  f"{first_el.sourceline}) and {jname!r}; a link may be the child of one "
                  "joint only", j)
            continue
        parent_of[child] = (jname, j)
        children.setdefault(parent, []).append(child)
    if not links:
        return
    roots = [n for n in links if n not in parent_of]
    if len(roots) > 1:
        r.add("U205", "error", f"{len(roots)} root links ({', '.join(map(repr, roots[:5]))}"
              f"{', ...' if len(roots) > 5 else ''}); connect them with joints so exactly one "
              "link has no parent", links[roots[1]])
    elif not roots:
        r.add("U206", "error", "no root link: every link is some joint's child, so the joints "
              "form a cycle", root)
    # Anything not reachable from a root sits on a cycle.
    reachable: set[str] = set()
    stack = list(roots)
    while stack:
        n = stack.pop()
        if n in reachable:
            continue
        reachable.add(n)
        stack.extend(children.get(n, []))
    cyclic = [n for n in links if n not in reachable]
    if cyclic and roots:
        j = parent_of[cyclic[0]][1]
        r.add("U207", "error", f"kinematic cycle through link(s) "
              f"{', '.join(map(repr, cyclic[:5]))}; joints must form a tree", j)


def rule_link_count(root: etree._Element, r: Report) -> None:
    """U208: 128 links or more break PyBullet's state queries."""
    n = sum(1 for _ in _elements(root, "link"))
    if n >= MAX_PYBULLET_LINKS:
        r.add("U208", "error", f"{n} links: PyBullet's getJointState/getLinkState fail on "
              f"bodies with {MAX_PYBULLET_LINKS} links or more (MAX_DEGREE_OF_FREEDOM); split "
              "the model", root)


#: Rules that stand between a file and a PyBullet crash, in order.
GUARD_RULES: tuple[Rule, ...] = (rule_document, rule_names, rule_tree)


def run_rules(root: etree._Element, file: str, rules: tuple[Rule, ...]) -> list[Finding]:
    """Run ``rules`` over a document root and return the findings."""
    report = Report(file)
    for rule in rules:
        rule(root, report)
    return report.findings


def guard(tree: etree._ElementTree | etree._Element, file: str) -> None:
    """Raise :class:`InputError` for the first finding that would crash PyBullet."""
    root = tree.getroot() if isinstance(tree, etree._ElementTree) else tree
    for f in run_rules(root, file, GUARD_RULES):
        if f.level == "error":
            raise InputError(f.message, file=f.file, line=f.line)

"""The kinematic tree of a URDF document, numbered the way PyBullet will number it.

Needs no PyBullet: it reads the guarded lxml document. PyBullet indexes joints depth-first from
the root, each link's children in file order, so a pre-order walk of this tree gives each
joint the index ``p.getJointInfo`` will report for it. ``urdfkit tree`` draws it and ``urdfkit
tree --dot`` (:mod:`urdfkit.draw.graph`) exports it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from lxml import etree

from urdfkit.model.spec import (
    AXIS_JOINT_TYPES,
    LIMITED_JOINT_TYPES,
    attr_float,
    attr_vec,
    depth_first,
)
from urdfkit.model.xmlio import children, line_of

Vec3 = tuple[float, float, float]

@dataclass
class TreeJoint:
    """A ``<joint>`` as the tree shows it.

    Attributes:
        index: The index PyBullet will give this joint (depth-first, file order).
        axis: ``<axis xyz>``, ``None`` for joint types that have no axis.
        limit: (lower, upper) from ``<limit>``, ``None`` when absent or continuous.
    """

    name: str
    type: str
    index: int
    xyz: Vec3
    rpy: Vec3
    axis: Vec3 | None
    limit: tuple[float, float] | None
    line: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        return {"name": self.name, "type": self.type, "index": self.index,
                "xyz": list(self.xyz), "rpy": list(self.rpy),
                "axis": list(self.axis) if self.axis is not None else None,
                "limit": list(self.limit) if self.limit is not None else None}


@dataclass
class TreeNode:
    """A link and the joints hanging below it.

    Attributes:
        link: The link's name.
        joint: The joint that attaches this link to its parent; ``None`` at the root.
        children: Child nodes in file order, which is PyBullet's index order.
    """

    link: str
    joint: TreeJoint | None = None
    children: list[TreeNode] = field(default_factory=list)

    # Iterative, not recursive: the guard admits chains of up to 1000 links, deeper than
    # Python's recursion limit.
    def walk(self) -> Iterator[TreeNode]:
        """Every node, depth-first (PyBullet's joint order after the root)."""
        stack = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children))

    def to_flat_dict(self) -> dict[str, Any]:
        """The JSON form, flat: links depth-first, joints in PyBullet's index order.

        Each joint names its ``parent`` and ``child`` link, so the tree is rebuilt with one
        dict; flat, the JSON stays linear in size however deep the chain (nested and
        indented, a 1000-link chain costs megabytes of indentation).
        """
        links: list[str] = []
        joints: list[dict[str, Any]] = []
        stack: list[tuple[TreeNode, str | None]] = [(self, None)]
        while stack:
            node, parent = stack.pop()
            links.append(node.link)
            if node.joint is not None:
                joints.append({**node.joint.to_dict(), "parent": parent, "child": node.link})
            stack.extend((child, node.link) for child in reversed(node.children))
        return {"base_link": self.link, "links": links, "joints": joints}


def kinematic_tree(root: etree._Element) -> TreeNode:
    """The link tree of a guarded ``<robot>`` document, with PyBullet's joint indices.

    Needs no PyBullet. The document must have passed :func:`urdfkit.sources.guard.guard` (one
    root, single parents, no cycle); :func:`urdfkit.sources.resolve.resolve` ensures that.
    """
    links = [el.get("name", "") for el in children(root, "link")]
    below: dict[str, list[etree._Element]] = {}
    has_parent: set[str] = set()
    for j in children(root, "joint"):
        parent = j.find("parent")
        child = j.find("child")
        if parent is None or child is None:
            continue
        below.setdefault(parent.get("link", ""), []).append(j)
        has_parent.add(child.get("link", ""))
    root_link = next((n for n in links if n not in has_parent), links[0] if links else "")
    top = TreeNode(root_link)
    nodes = {root_link: top}
    for index, j in enumerate(depth_first(root_link, below, _child_link)):
        node = TreeNode(_child_link(j), _tree_joint(j, index))
        nodes[_parent_link(j)].children.append(node)
        nodes[node.link] = node
    return top


def _child_link(j: etree._Element) -> str:
    el = j.find("child")
    return el.get("link", "") if el is not None else ""


def _parent_link(j: etree._Element) -> str:
    el = j.find("parent")
    return el.get("link", "") if el is not None else ""


def _tree_joint(j: etree._Element, index: int) -> TreeJoint:
    jtype = j.get("type", "")
    origin = j.find("origin")
    axis = attr_vec(j.find("axis"), "xyz", 3, (1, 0, 0)) if jtype in AXIS_JOINT_TYPES else None
    limit_el = j.find("limit")
    limit = None
    if jtype in LIMITED_JOINT_TYPES and limit_el is not None:
        limit = (attr_float(limit_el, "lower", 0.0), attr_float(limit_el, "upper", 0.0))
    return TreeJoint(j.get("name", ""), jtype, index,
                     attr_vec(origin, "xyz", 3, (0, 0, 0)),  # type: ignore[arg-type]
                     attr_vec(origin, "rpy", 3, (0, 0, 0)),  # type: ignore[arg-type]
                     axis, limit, line_of(j))  # type: ignore[arg-type]

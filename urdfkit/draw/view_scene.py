"""The robot in the view's 3D scene: its link frames and, under each, the nodes of its layers.

:class:`RobotScene` draws a :class:`~urdfkit.draw.view_model.ViewedRobot` under ``/robot``:
a frame per link, posed where PyBullet has it, holding the link's visual and collision shapes
(:func:`add_shapes`), its axes and joint axis (the ``frames`` layer), and its centre of mass
and inertia box (the ``inertia`` layer). It shows or hides each layer, moves the frames, and
colours the shapes; what to show, where and in which colour is the viewer's
(:class:`urdfkit.draw.view.Viewer`) to say.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from urdfkit.draw.view_model import SELECTED_RGB, TINTS, TOUCHING_RGB, Layer, Vec3, ViewedRobot

#: How much larger collision shapes are drawn than they are (see :func:`add_shapes`).
COLLISION_INFLATE = 1.005


def wxyz(q: Sequence[float]) -> tuple[float, float, float, float]:
    """A PyBullet quaternion (x, y, z, w) as viser takes it (w, x, y, z)."""
    return (float(q[3]), float(q[0]), float(q[1]), float(q[2]))


def add_shapes(scene: Any, root: str, link: Any, tint: tuple[int, int, int] | None
                ) -> list[tuple[Layer, Any]]:
    """A link's visual and collision meshes under its frame ``root``: (kind, handle) pairs."""
    out: list[tuple[Layer, Any]] = []
    layers: tuple[tuple[Layer, Any], ...] = (("visual", link.visuals),
                                             ("collision", link.collisions))
    for kind, shapes in layers:
        for k, sh in enumerate(shapes):
            vertices = sh.vertices
            if kind == "collision" and len(vertices):
                # A collision box on its visual box would z-fight (both drawn, the faces
                # flicker): drawn 0.5% larger about its middle, the pair shows as one.
                mid = (vertices.max(axis=0) + vertices.min(axis=0)) / 2
                vertices = mid + (vertices - mid) * COLLISION_INFLATE
            out.append((kind, scene.add_mesh_simple(
                f"{root}/{kind}{k}", vertices, sh.faces, color=tint or sh.rgb,
                opacity=None if sh.opacity >= 1 else sh.opacity,
                # No shadow pass: it doubles the first draw in software WebGL.
                cast_shadow=False, receive_shadow=False,
                position=sh.pos, wxyz=wxyz(sh.quat))))
    return out


class RobotScene:
    """The scene nodes of the robot on show, by layer, and its link frames.

    The caller holds the viewer's lock (and, to move many nodes at once, viser's ``atomic``).
    """

    def __init__(self, scene: Any) -> None:
        #: viser's scene.
        self.scene = scene
        #: Every shape and marker node by layer: the robot's, and the shapes of more robots a
        #: run adds (:meth:`urdfkit.draw.view_stream.RunDisplay.add_robot`).
        self.nodes: dict[Layer, list[Any]] = {}
        #: The robot's link frames, in link order: each holds its link's nodes.
        self.frames: list[Any] = []
        #: The length of the axes a link frame is drawn with: the robot's scale.
        self.frame_size = 0.0

    def clear(self) -> None:
        """Remove the robot's nodes (a link's frame takes its nodes with it)."""
        for h in self.frames:
            h.remove()
        self.nodes = {"visual": [], "collision": [], "frames": [], "inertia": []}
        self.frames = []

    def draw(self, model: ViewedRobot, clicked: Callable[[str], Any]) -> None:
        """Each link's frame, shapes, axes, joint axis, centre of mass and inertia box.

        ``clicked(link name)`` is each shape's click callback: clicking a link selects it.
        """
        import numpy as np

        from urdfkit.model.spec import quat_to_matrix, rotate

        scene, m = self.scene, model
        size = max(max(hi - lo for lo, hi in zip(*m.bounds(), strict=True)), 0.05)
        self.frame_size = size * 0.15
        by_index = {j.link: j for j in m.joints}
        for link, (pos, quat) in zip(m.links, m.link_poses(), strict=True):
            root = f"/robot/link{link.index + 1}"
            self.frames.append(scene.add_frame(root, show_axes=False, position=pos,
                                               wxyz=wxyz(quat)))
            for kind, mesh in add_shapes(scene, root, link, None):
                # Clicking a link in the scene selects it (and its joint's row).
                mesh.on_click(clicked(link.name))
                self.nodes[kind].append(mesh)
            self.nodes["frames"].append(scene.add_frame(
                f"{root}/axes", axes_length=self.frame_size, axes_radius=size * 0.006))
            joint = by_index.get(link.index)
            if joint is not None:  # PyBullet's axis is in the inertial frame: into the link's
                axis = np.asarray(rotate(quat_to_matrix(link.inertial_quat), joint.axis),
                                  dtype=float)
                points = np.array([[-axis, axis]], dtype=np.float32) * size * 0.2
                self.nodes["frames"].append(scene.add_line_segments(
                    f"{root}/joint_axis", points, (204, 121, 167), thickness=size * 0.006))
            self.nodes["inertia"].append(scene.add_frame(
                f"{root}/com", show_axes=False, position=link.inertial_pos,
                wxyz=wxyz(link.inertial_quat)))
            self.nodes["inertia"].append(scene.add_icosphere(
                f"{root}/com/dot", radius=size * 0.012, color=(20, 20, 20)))
            if link.inertia_box is not None:
                self.nodes["inertia"].append(scene.add_box(
                    f"{root}/com/box", dimensions=link.inertia_box, color=(0, 114, 178),
                    opacity=0.35))

    def show(self, want: Mapping[Layer, bool]) -> None:
        """Show or hide each layer."""
        for kind, handles in self.nodes.items():
            for h in handles:
                h.visible = bool(want[kind])

    def visible(self, kind: Layer) -> bool:
        """Whether a layer is shown."""
        handles = self.nodes.get(kind, [])
        return bool(handles) and all(h.visible for h in handles)

    def move(self, poses: Iterable[tuple[Any, Sequence[float]]]) -> None:
        """Put each link frame at its pose (position, PyBullet's xyzw), in link order."""
        for frame, (pos, quat) in zip(self.frames, poses, strict=True):
            frame.position = pos
            frame.wxyz = wxyz(quat)

    def recolour(self, model: ViewedRobot, selected: str | None, hit: set[str],
                 tint: bool) -> None:
        """Each link's colour: selected, touching (in ``hit``), its findings' tint, or its own."""
        for link, k in zip(model.links, range(len(model.links)), strict=True):
            base = TINTS.get(link.level or "") if tint else None
            layers: tuple[tuple[Layer, Any], ...] = (("visual", link.visuals),
                                                     ("collision", link.collisions))
            for kind, shapes in layers:
                handles = [h for h in self.nodes.get(kind, [])
                           if h.name.startswith(f"/robot/link{k}/")]
                for h, sh in zip(handles, shapes, strict=True):
                    want = SELECTED_RGB if link.name == selected else \
                        TOUCHING_RGB if link.name in hit else (base or sh.rgb)
                    if tuple(h.color) != tuple(want):
                        h.color = want

    def link_pose(self, model: ViewedRobot, name: str
                  ) -> tuple[Vec3, tuple[float, float, float, float]]:
        """A link node's pose in the scene: (position, wxyz)."""
        for link, frame in zip(model.links, self.frames, strict=True):
            if link.name == name:
                return (tuple(float(x) for x in frame.position),  # type: ignore[return-value]
                        tuple(float(x) for x in frame.wxyz))
        raise KeyError(name)

    def of(self, model: ViewedRobot, kind: Layer, link: str) -> list[Any]:
        """The nodes of one layer of one link."""
        index = next(i for i, lk in enumerate(model.links) if lk.name == link)
        prefix = f"/robot/link{index}/"
        return [h for h in self.nodes.get(kind, []) if h.name.startswith(prefix)]

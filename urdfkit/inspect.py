"""Turn a loaded body into plain data: the joint table, and the report every command fills.

Everything here returns dataclasses; nothing prints. ``cli.py`` presents them as rich tables
or JSON. This module is the public face of the inspector: the joint table is in
:mod:`urdfkit.engine.joints`, the link table and the summary in :mod:`urdfkit.engine.body`, the
kinematic tree (no PyBullet) in :mod:`urdfkit.draw.tree`, and loading a file into a report in
:mod:`urdfkit.engine.report`, so that ``urdfkit joints`` loads only what it shows.

The joint table carries all 17 fields of ``p.getJointInfo`` under the names the PyBullet
Quickstart Guide uses (``jointIndex`` ... ``parentIndex``); :meth:`JointInfo.to_dict` is the
JSON contract of ``urdfkit joints --json`` (see ``docs/inspect.md``).
"""

from __future__ import annotations

from urdfkit.engine.joints import (
    JOINT_INFO_FIELDS,
    JointInfo,
    Quat,
    Vec3,
    base_link_name,
    filter_joints,
    joint_table,
    pose_joints,
)

__all__ = ["JOINT_INFO_FIELDS", "JointInfo", "Quat", "Vec3", "base_link_name", "filter_joints",
           "joint_table", "pose_joints"]

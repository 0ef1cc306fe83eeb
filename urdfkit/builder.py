"""A typed model of a URDF robot, and its XML.

The classes are named after the URDF tags (:class:`Link`, :class:`Joint`, :class:`Inertial`,
:class:`Origin`, :class:`Limit`, :class:`Contact`, ...). Values are checked where they are set,
so a bad value fails at the line that set it, naming the tag and the attribute::

    >>> Box(size=(1, -2, 3))
    Traceback (most recent call last):
    ...
    urdfkit.core.errors.ModelError: during assignment to attribute 'size' of element <box>: ...

Inertia is derived from the collision shapes and the mass (solid box, cylinder, sphere, with
shape offsets and rotations) unless it is given explicitly; see :meth:`Inertial.from_shapes`.

Writing is deterministic: fixed float precision, no ``-0``, a stable element order, pretty
printing. Declaration order is kept, because PyBullet numbers joints depth-first from the root,
taking each link's child joints in file order: declaring joints in the order you want their
indices gives you those indices. :meth:`Robot.pybullet_joint_order` predicts them.

Every tag has a ``_parse_*`` and a ``_write_*`` function side by side, and
``parse(write(robot)) == robot`` holds for everything the model holds.

Reading has a lenient mode for comparing what files say (``strict=False``, used by
``urdfkit diff``): a value the checks refuse is kept as written instead of failing the file
(:func:`as_written`). Building and writing stay strict.
"""

from __future__ import annotations

from urdfkit.model.robot import (
    JOINT_TYPES,
    LIMITED_JOINT_TYPES,
    SHAPE_CLASSES,
    Box,
    Calibration,
    Capsule,
    Cdf,
    Collision,
    Contact,
    Cylinder,
    Dynamics,
    Geometry,
    Inertia,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mesh,
    Mimic,
    Origin,
    Plane,
    Robot,
    SafetyController,
    Sphere,
    Visual,
    as_written,
    rpy_to_matrix,
)

#: The model API: every element class, the robot, and what spec lends it. The robot and its XML
#: live in :mod:`urdfkit.model.robot`, the elements in :mod:`urdfkit.model.builder_elements`.
__all__ = ["JOINT_TYPES", "LIMITED_JOINT_TYPES", "SHAPE_CLASSES", "Box", "Calibration", "Capsule",
           "Cdf", "Collision", "Contact", "Cylinder", "Dynamics", "Geometry", "Inertia",
           "Inertial", "Joint", "Limit", "Link", "Material", "Mesh", "Mimic", "Origin",
           "Plane", "Robot", "SafetyController", "Sphere", "Visual", "as_written",
           "rpy_to_matrix"]

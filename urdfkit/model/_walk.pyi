"""Doc's one walk over libxml2's nodes (``_walk.c``); see :mod:`urdfkit.model.index`."""

from collections.abc import Callable, Container
from typing import Any

LXML_VERSION: str

def walk(root: Any, tag: str, checked: bool, buckets: dict[str, list[Any]],
         findings: list[tuple[str, str, str, Any]],
         schema: dict[str, tuple[frozenset[str], frozenset[str]]],
         numeric: dict[str, dict[str, int]], opaque: Container[str], max_depth: int,
         verdicts: dict[Any, tuple[tuple[str, str, str], ...]], verdicts_max: int,
         verdict: Callable[[str, list[tuple[str, str]]], tuple[tuple[str, str, str], ...]],
         ) -> Any: ...

def first(el: Any, tag: str) -> Any: ...

def link_parts(link: Any) -> tuple[Any, Any, Any, list[Any], list[Any]]: ...

def joint_parts(joint: Any) -> tuple[Any, Any, list[Any], Any, Any, Any, Any]: ...

def collision_parts(collision: Any, shapes: tuple[str, ...]) -> tuple[Any, Any]: ...

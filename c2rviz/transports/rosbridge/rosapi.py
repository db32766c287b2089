"""The ``/rosapi/*`` services ROS clients call to look around, answered from a table (pure).

roslibpy's ``Ros.get_topics()``, ``get_topic_type()``, ``get_services()``,
``get_nodes()`` and ``Param.get()``, roslibjs's URDF loaders, and Foxglove's
and Lichtblick's Rosbridge connection (``/rosapi/topics_and_raw_types``) call
these. rosbridge answers them from the ROS graph; c2rviz answers them from a
``Graph`` its caller builds: the topics and services it has, its node and its
parameters. Answers follow ``rosapi_msgs/srv/*`` (ROS 2 rosapi): a topic or
service that does not exist has type ``""``; a parameter's value is JSON text.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ...errors import C2rvizError
from .messages import TypeNameError, normalize_type
from .msg_definitions import full_text
from .protocol import resolve_name

__all__ = ["ROSAPI_SERVICES", "Graph", "RosapiError", "answer", "is_rosapi"]


class RosapiError(C2rvizError):
    """A rosapi call c2rviz cannot answer (an unknown parameter, a mistyped field)."""


@dataclass(frozen=True)
class Graph:
    """What c2rviz shows of itself as a ROS graph.

    Attributes:
        topics: ``(name, type)`` of every topic, absolute names, ``pkg/msg/Name`` types.
        services: ``(name, type)`` of the services besides rosapi's own.
        nodes: The node names (``/c2rviz``).
        params: Parameter values by name (``robot_description``: the URDF text).
    """

    topics: tuple[tuple[str, str], ...] = ()
    services: tuple[tuple[str, str], ...] = ()
    nodes: tuple[str, ...] = ("/c2rviz",)
    params: Mapping[str, object] = field(default_factory=dict)


def _text(args: Mapping[str, Any], name: str, service: str) -> str:
    value = args.get(name, "")
    if not isinstance(value, str):
        raise RosapiError(f"{service}: {name} must be a string")
    return value


def _topics(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"topics": [t for t, _ in graph.topics], "types": [k for _, k in graph.topics]}


def _topics_and_raw_types(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    answer = _topics(graph, args)
    answer["typedefs_full_text"] = [full_text(k) for k in answer["types"]]
    return answer


def _topic_type(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    topic = _text(args, "topic", "/rosapi/topic_type")
    wanted = resolve_name(topic) if topic else ""
    return {"type": next((k for t, k in graph.topics if t == wanted), "")}


def _topics_for_type(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    try:
        wanted = normalize_type(_text(args, "type", "/rosapi/topics_for_type"))
    except TypeNameError:
        return {"topics": []}  # no topic has a type that is not one
    return {"topics": [t for t, k in graph.topics if k == wanted]}


def _all_services(graph: Graph) -> list[tuple[str, str]]:
    return [*graph.services, *ROSAPI_SERVICES.items()]


def _services(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"services": [s for s, _ in _all_services(graph)]}


def _service_type(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    service = _text(args, "service", "/rosapi/service_type")
    wanted = resolve_name(service) if service else ""
    return {"type": next((k for s, k in _all_services(graph) if s == wanted), "")}


def _nodes(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"nodes": list(graph.nodes)}


def _param_name(name: str) -> str:
    """``robot_description`` for ``robot_description``, ``/robot_description`` or
    ``/node:robot_description`` (ROS 2 rosapi's ``node:param``; any node of ours)."""
    return name.rsplit(":", 1)[-1].lstrip("/")


def _get_param(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    name = _text(args, "name", "/rosapi/get_param")
    default = _text(args, "default_value", "/rosapi/get_param")
    key = _param_name(name)
    if key in graph.params:
        return {"value": json.dumps(graph.params[key])}
    if default:
        return {"value": default}  # rosapi hands the default back as given (JSON text)
    known = ", ".join(sorted(graph.params)) or "none"
    raise RosapiError(f"/rosapi/get_param: no parameter {name!r} (parameters: {known})")


def _has_param(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"exists": _param_name(_text(args, "name", "/rosapi/has_param")) in graph.params}


def _param_names(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    node = graph.nodes[0] if graph.nodes else ""
    return {"names": [f"{node}:{name}" for name in sorted(graph.params)]}


_Answer = Callable[[Graph, Mapping[str, Any]], dict[str, Any]]
_ANSWERS: dict[str, tuple[str, _Answer]] = {
    "/rosapi/topics": ("Topics", _topics),
    "/rosapi/topics_and_raw_types": ("TopicsAndRawTypes", _topics_and_raw_types),
    "/rosapi/topic_type": ("TopicType", _topic_type),
    "/rosapi/topics_for_type": ("TopicsForType", _topics_for_type),
    "/rosapi/services": ("Services", _services),
    "/rosapi/service_type": ("ServiceType", _service_type),
    "/rosapi/nodes": ("Nodes", _nodes),
    "/rosapi/get_param": ("GetParam", _get_param),
    "/rosapi/has_param": ("HasParam", _has_param),
    "/rosapi/get_param_names": ("GetParamNames", _param_names),
}
ROSAPI_SERVICES: dict[str, str] = {
    name: f"rosapi_msgs/srv/{kind}" for name, (kind, _) in _ANSWERS.items()
}
"""The rosapi services c2rviz answers, with their ROS 2 types."""


def is_rosapi(service: str) -> bool:
    """Whether ``service`` (absolute) is one of the rosapi services answered here."""
    return service in _ANSWERS


def answer(service: str, args: Mapping[str, Any], graph: Graph) -> dict[str, Any]:
    """The response ``values`` of rosapi ``service`` called with ``args``.

    Args:
        service: An absolute service name for which ``is_rosapi`` holds.
        args: The request's fields (unknown fields are ignored, as rosapi does).
        graph: What there is to tell.

    Raises:
        RosapiError: Not a rosapi service answered here, a field of the wrong
            type, or ``get_param`` of an unknown parameter without a default.
    """
    entry = _ANSWERS.get(service)
    if entry is None:
        raise RosapiError(
            f"{service} is not a rosapi service c2rviz answers (it answers: {', '.join(_ANSWERS)})"
        )
    return entry[1](graph, args)

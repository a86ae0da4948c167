"""Node parameters as ROS users type them: ``-p speedup:=2`` is a double, ``-p seed:=1.5`` a clear error.

rclpy fixes a parameter's type from its default, so ``speedup:=2`` (an integer) for a double parameter raises
``InvalidParameterTypeException`` with a traceback, and ``ros2 param set`` of an integer is refused. Here each
parameter is declared with dynamic typing and checked against its :class:`ParameterSpec`: an integer where a
double is wanted is widened (as every ROS 2 user expects), anything else of the wrong type is refused with one
line naming the parameter, the type it takes and what it got, at start (:class:`ParameterTypeError`) and when
set at run time (the set is refused with that reason). Parameters that only take effect at start are
read-only, so a run-time set says so instead of silently doing nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

_TYPE_NAMES = {bool: "a boolean (true/false)", int: "an integer", float: "a double", str: "a string",
               list: "a list of doubles"}


class ParameterTypeError(ValueError):
    """A parameter given a value of a type it cannot take."""


@dataclass(frozen=True)
class ParameterSpec:
    """One node parameter: its name, default (whose type is the parameter's), meaning, and whether a set at run
    time is applied (``on_change``) or refused (read-only)."""

    name: str
    default: bool | int | float | str | list[float]
    description: str
    on_change: Callable[[Any], None] | None = None


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def coerce(spec: ParameterSpec, value: Any) -> bool | int | float | str | list[float]:
    """``value`` as the spec's type: an integer widens to a double (also in a list of doubles); a bool is never
    taken for a number."""
    wanted = type(spec.default)
    if wanted is float and _is_number(value):
        return float(value)
    if wanted is list and not isinstance(value, str | bytes) and hasattr(value, "__iter__") and all(
            _is_number(v) for v in value):
        return [float(v) for v in value]
    if wanted is not list and isinstance(value, wanted) and (wanted is bool or not isinstance(value, bool)):
        return value
    raise ParameterTypeError(
        f"parameter '{spec.name}' takes {_TYPE_NAMES[wanted]}, not {value!r} ({type(value).__name__})")


def declare_parameters(node: Node, specs: list[ParameterSpec]) -> dict[str, Any]:
    """Declare ``specs`` on ``node`` and return their values (overrides from the command line applied);
    raises ParameterTypeError for the first override of a wrong type. Run-time sets are checked from now on."""
    values = {}
    for spec in specs:
        descriptor = ParameterDescriptor(description=spec.description, dynamic_typing=True,
                                         read_only=spec.on_change is None)
        values[spec.name] = coerce(spec, node.declare_parameter(spec.name, spec.default, descriptor).value)
    by_name = {spec.name: spec for spec in specs}
    node.add_on_set_parameters_callback(lambda params: _on_set(by_name, params))
    return values


def _on_set(specs: dict[str, ParameterSpec], params: list[Parameter]) -> SetParametersResult:
    """Refuse a run-time value of the wrong type (one line, the same as at start); apply the others."""
    changes = []
    for param in params:
        spec = specs.get(param.name)
        if spec is None:
            continue
        try:
            changes.append((spec, coerce(spec, param.value)))
        except ParameterTypeError as error:
            return SetParametersResult(successful=False, reason=str(error))
    for spec, value in changes:
        if spec.on_change is not None:
            spec.on_change(value)
    return SetParametersResult(successful=True)

"""Reading the type-specific keys of position models and rangers (spec §6.2, §6.4, §7.1, §7.2).

Kept apart from the tree walk in :mod:`stage_sim.worldfile.loader` because this is where Stage 3 and
Stage 4 differ most, and each difference needs its own warning.
"""

from __future__ import annotations

import math

from stage_sim.worldfile.description import Pose, PositionSettings, Sensor
from stage_sim.worldfile.drive_names import DRIVE_NAMES
from stage_sim.worldfile.errors import SourceLocation
from stage_sim.worldfile.keys import Properties

LOCALIZATIONS = ("gps", "odom")
RANGER_LEVEL_KEYS = ("range", "fov", "samples", "noise")
"""Sensor keys that Stage 4 reads only inside ``sensor( )`` but old worlds put on the ranger itself."""

LASER_SAMPLES = 180
LASER_RANGE_MAX = 8.0
LASER_FOV = math.pi


def read_sensor(props: Properties) -> Sensor:
    """One ``sensor( )`` block with Stage 4's defaults (fov 0.1 rad: the default is not in degrees)."""
    defaults = Sensor()
    size = props.lengths("size", 3)
    if size is not None:
        props.require(min(size) >= 0, "size", list(size), "sizes >= 0")
    sensor = Sensor(
        pose=props.pose("pose", Pose()) or Pose(),
        size=(size[0], size[1], size[2]) if size is not None else defaults.size,
        color=props.color(defaults.color),
        **_beam_fields(props),
    )
    props.report_unread("a sensor")
    return sensor


def _beam_fields(props: Properties) -> dict:
    """samples, range, fov and noise with Stage 4's sensor defaults, checked so ray casting cannot break."""
    defaults = Sensor()
    samples = props.integer("samples", defaults.samples)
    if "samples" in props:
        props.require(samples >= 1, "samples", samples, "at least 1 sample")
    span = props.lengths("range", 2) or (defaults.range_min, defaults.range_max)
    if "range" in props:
        props.require(
            0 <= span[0] <= span[1] and span[1] > 0, "range", list(span), "[min max] with 0 <= min <= max and max > 0"
        )
    fov = props.angle("fov", defaults.fov)
    if "fov" in props:
        props.require(fov >= 0, "fov", fov, "a field of view >= 0")
    noise = props.numbers("noise", 3, [1.0, 1.0, props.units.angle]) or defaults.noise
    return {
        "samples": samples,
        "range_min": span[0],
        "range_max": span[1],
        "fov": fov,
        "noise": (noise[0], noise[1], noise[2]),
    }


def ranger_sensors(props: Properties, sensors: list[Sensor], laser: bool, where: SourceLocation) -> list[Sensor]:
    """The transducers of a ranger, including the two Stage 3 forms read with a warning.

    * Stage 3 ``laser( samples range_max fov )`` (Stage 4 refuses the type): one sensor with the laser's
      keys, defaults 180 samples, 8 m, 180°; ``sensor( )`` blocks, if any, take precedence.
    * A ranger with ``range``/``fov``/``samples``/``noise`` on itself and no ``sensor( )``: Stage 4
      ignores those keys and would have no transducer; here they become its single sensor, which is what
      the author meant. With ``sensor( )`` blocks present they are ignored, as in Stage 4.
    """
    warnings = props.warnings
    if laser:
        count = props.integer("samples", LASER_SAMPLES)
        range_min = props.length("range_min", 0.0)
        range_max = props.length("range_max", LASER_RANGE_MAX)
        fov = props.angle("fov", LASER_FOV)
        for key, ok, value, expected in (
            ("samples", count >= 1, count, "at least 1 sample"),
            ("range_min", 0 <= range_min <= range_max, range_min, ">= 0 and <= range_max"),
            ("range_max", range_max > 0, range_max, "> 0"),
            ("fov", fov >= 0, fov, "a field of view >= 0"),
        ):
            if key in props:
                props.require(ok, key, value, expected)
        refused = "Stage 4 has no 'laser' type and refuses this world"
        if sensors:
            warnings.add(f"Stage 3 'laser' model read as a ranger with its sensor( ) blocks; {refused}", where)
            return sensors
        warnings.add(
            f"Stage 3 'laser' model read as a ranger with one sensor ({count} samples, range "
            f"[{range_min:g} {range_max:g}] m, fov {math.degrees(fov):g} deg); {refused}",
            where,
        )
        return [Sensor(samples=count, range_min=range_min, range_max=range_max, fov=fov)]
    present = [key for key in RANGER_LEVEL_KEYS if key in props]
    if present and not sensors:
        keys = ", ".join(present)
        warnings.add(
            f"ranger-level {keys} read as this ranger's single sensor (Stage 4 ignores keys outside sensor( ) "
            "and would give it none)",
            props.location(present[0]),
        )
        return [Sensor(**_beam_fields(props))]
    for key in present:
        props.take(key)
        warnings.add(f"ranger-level '{key}' ignored: Stage 4 reads it only inside sensor( )", props.location(key))
    if not sensors:
        warnings.add("ranger without sensor( ): it produces no scans", where)
    return sensors


def position_settings(props: Properties) -> PositionSettings:
    """Position-only keys (spec §6): drive, bounds, localization, odom_error, wheelbase."""
    defaults = PositionSettings()
    length, angle = props.units.length, props.units.angle
    bound_scales = [length] * 6 + [angle] * 2
    bounds = {}
    for key in ("velocity_bounds", "acceleration_bounds"):
        values = props.numbers(key, 8, bound_scales)
        if values is not None:
            props.require(
                all(values[i] <= values[i + 1] for i in range(0, 8, 2)),
                key,
                list(values),
                "[xmin xmax ymin ymax zmin zmax amin amax] with each min <= max",
            )
        bounds[key] = values if values is not None else getattr(defaults, key)
    odom_error = props.numbers("odom_error", 4, [1.0, 1.0, 1.0, angle])
    wheelbase = props.length("wheelbase", defaults.wheelbase)
    if "wheelbase" in props:
        props.require(wheelbase > 0, "wheelbase", wheelbase, "a wheelbase > 0 m")
    return PositionSettings(
        drive=props.choice("drive", defaults.drive, DRIVE_NAMES),
        velocity_bounds=bounds["velocity_bounds"],
        acceleration_bounds=bounds["acceleration_bounds"],
        localization=props.choice("localization", defaults.localization, LOCALIZATIONS),
        localization_origin=props.pose("localization_origin", None),
        odom_error=(odom_error[0], odom_error[1], odom_error[2], odom_error[3]) if odom_error else None,
        wheelbase=wheelbase,
    )

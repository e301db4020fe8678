"""`actuator-fmus pressure-for-force FORCE_N LENGTH_M [--set name=value ...]`."""

import json

from .inverse import pressure_for_force
from .paths import UsageError


def add_arguments(parser):
    """The options of `actuator-fmus pressure-for-force` (force in N, length in m, pressure in Pa)."""
    parser.add_argument("force", type=float, help="tension force, N")
    parser.add_argument("length", type=float, help="muscle length, m")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="a McKibbenMuscle parameter in SI units, e.g. --set preset=DMSP_40 (repeatable)")
    parser.add_argument("--max-pressure", type=float, default=8e5, help="highest gauge pressure allowed, Pa (default 8e5)")


def main(args):
    """Prints the pressure in Pa and kPa, and whether the force is out of reach; returns 0."""
    start = {}
    for item in args.set:
        name, sep, text = item.partition("=")
        if not sep:
            raise UsageError(f"--set {item!r}: write NAME=VALUE, e.g. --set preset=DMSP_40")
        try:
            start[name] = json.loads(text)
        except ValueError:
            start[name] = text  # an Enumeration item's name
    pressure_pa, out_of_reach = pressure_for_force(args.force, args.length, start, args.max_pressure)
    print(f"{pressure_pa:.6g} Pa ({pressure_pa / 1e3:.5g} kPa)"
          + ("  out of reach: the pressure of the nearest force" if out_of_reach else ""))
    return 0

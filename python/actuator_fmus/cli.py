"""`actuator-fmus`: the project's jobs from the command line. `actuator-fmus --help` lists them.

A mistake (a misspelt name, a value outside its declared range, a missing FMU) prints one line
that says what is valid and exits 2; a failed check of a scene against the dissertation exits 1.
"""

import argparse
import importlib
import sys

from .paths import UsageError

# (command, module, one line of help). Each module has main(args) and, if it takes options,
# add_arguments(parser).
COMMANDS = [
    ("scene", "scene", "run scene files under FMPy: <out>/<scene>.csv and .png, the dissertation's numbers checked"),
    ("figures", "catalogue", "run every scene in scenes/ and write docs/figures.md"),
    ("info", "cli_info", "a packaged FMU's variables: causality, unit, range, named choices"),
    ("calibrate", "calibration", "fit McKibbenMuscle to a datasheet CSV and check the fit through the FMU"),
    ("pressure-for-force", "cli_pressure", "gauge pressure (Pa) at which McKibbenMuscle pulls a force (N) at a length (m)"),
    ("crosscheck", "crosscheck", "write the FMI cross-check files crosscheck/<Model>/ and docs/fmu/<Model>.png"),
    ("robot-joint", "robot_joint", "antagonistic muscle pair on a pulley under PD control: out/robot_joint.{csv,png}"),
    ("systems", "systems", "the robot joint as an SSP and as a container FMU: out/systems/"),
    ("sweep", "sweep", "design sweep on Dask: bladder pre-strain x wall thickness -> net work: out/sweep.{csv,png}"),
    ("knitted-bag", "knitted_bag", "docs/knitted-bag.md: the section 1.4 prototype's bag and its stroke"),
    ("motor", "motor", "docs/motor.md: the MultiferroicMotor's stepper characteristics"),
    ("linearized", "linearized", "docs/linearized-muscle.md: stiffness and pressure gain over the stroke"),
    ("chapter2-claims", "chapter2", "docs/chapter2-claims.md: chapter 2's claims with the dissertation's walls and the exact wall"),
]


def parser():
    """The argparse parser of `actuator-fmus` with one subcommand per entry of COMMANDS."""
    p = argparse.ArgumentParser(prog="actuator-fmus", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module, help_text in COMMANDS:
        mod = importlib.import_module(f".{module}", __package__)
        command = sub.add_parser(name, help=help_text, description=help_text)
        if hasattr(mod, "add_arguments"):
            mod.add_arguments(command)
        command.set_defaults(run=mod.main)
    return p


def main(argv=None):
    """Runs `actuator-fmus` with `argv`; returns the exit status (2 and one line on a UsageError)."""
    args = parser().parse_args(argv)
    try:
        return args.run(args) or 0
    except UsageError as e:
        print(f"actuator-fmus {args.command}: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())

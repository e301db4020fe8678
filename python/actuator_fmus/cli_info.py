"""`actuator-fmus info MODEL`: what a packaged FMU takes and gives, as its model description says."""

from . import names as checks
from .paths import FMU_DIR, UsageError, models


def add_arguments(parser):
    """The options of `actuator-fmus info`."""
    parser.add_argument("model", nargs="?", help="FMU name (none: list the packaged FMUs)")


def main(args):
    """Prints the variables of `args.model` (units SI); without a model, the FMUs in FMU_DIR."""
    if not args.model:
        found = models()
        if not found:
            raise UsageError(f"no FMUs in {FMU_DIR}: run `make fmus` first")
        print("\n".join(found))
        return 0
    md = checks.model_description(args.model)
    interfaces = [k for k, v in (("Co-Simulation", md.coSimulation), ("Model Exchange", md.modelExchange)) if v]
    print(f"{md.modelName} (FMI {md.fmiVersion}: {', '.join(interfaces)}): {md.description}")
    for causality in ("input", "output", "parameter", "calculatedParameter"):
        chosen = [v for v in md.modelVariables if v.causality == causality]
        if not chosen:
            continue
        print(f"\n{causality}s:")
        for v in chosen:
            lo, hi = checks.declared_range(v)
            items = checks.enumeration_items(v)
            if items:
                what = "one of " + ", ".join(f"{n} ({k})" for n, k in items.items())
            else:
                unit = checks.unit(v) or ("" if checks.fmi2_type(v) != "Real" else "1")
                span = "" if lo is None and hi is None else \
                    f" {'' if lo is None else f'{lo:g}'} .. {'' if hi is None else f'{hi:g}'}"
                what = f"{v.type}{span} {unit}".rstrip()
            start = "" if v.start is None else f", start {v.start}" + "".join(
                f" ({n})" for n, k in items.items() if str(k) == str(v.start))
            print(f"  {v.name}: {what}{start}")
    return 0

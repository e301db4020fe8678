"""Recipe: the gauge pressure that makes McKibbenMuscle pull a given force at a given contraction.

Muscle A of Table 2.1 (the dissertation), the exact thick-walled bladder (bladder_model 3, 16 nodes: its
1.6 mm wall on a 1.6 mm bore is thick, Fig. 2.11). Contraction counts from the length at rest,
unpressurized and unloaded. Two readings of that length, both printed:

1. the listed 103.25 mm, measured between the attachment points, so the connectors are part of
   it: with `connector_stiffness` = 2000 N/m the model reaches it (the `length` input is then the
   measured length, eq. section 2.4);
2. a rigid connector, where the rubber fills the sleeve at `max_length` (97.30 mm): contraction
   then counts from `max_length`.

Run after `make fmus`: .venv/bin/python recipes/pressure_for_force.py [force_N] [contraction]
"""
import shutil
import sys
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from scipy.optimize import brentq

FMU = Path(__file__).resolve().parents[1] / "target" / "fmu" / "McKibbenMuscle.fmu"
LISTED_LENGTH = 0.10325  # m, Table 2.1 muscle A


class Muscle:
    """One instance, initialized once; the force follows pressure and length between steps."""

    def __init__(self, **parameters):
        self.md = read_model_description(FMU)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.dir = extract(FMU)
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="m")
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        ints = {k: v for k, v in parameters.items() if k in ("preset", "bladder_model", "bladder_layers")}
        reals = {k: v for k, v in parameters.items() if k not in ints}
        self.fmu.setInteger([self.vr[k] for k in ints], list(ints.values()))
        self.fmu.setReal([self.vr[k] for k in reals], list(reals.values()))
        self.fmu.exitInitializationMode()

    def get(self, name):
        return self.fmu.getReal([self.vr[name]])[0]

    def force(self, pressure, length):
        self.fmu.setReal([self.vr["pressure"], self.vr["length"]], [pressure, length])
        return self.get("force")

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


def pressure_for(muscle, force, length, p_max=1.0e6):
    """Bisection-safe root of force(P) - target on [0, p_max] (force rises with pressure)."""
    lo = muscle.force(0.0, length) - force
    hi = muscle.force(p_max, length) - force
    if lo > 0 or hi < 0:
        return None, lo + force, hi + force
    return brentq(lambda p: muscle.force(p, length) - force, 0.0, p_max, xtol=1.0), None, None


def main():
    target = float(sys.argv[1]) if len(sys.argv) > 1 else 20.0
    contraction = float(sys.argv[2]) if len(sys.argv) > 2 else 0.08
    print(f"McKibbenMuscle, Table 2.1 muscle A, exact thick wall: {target:g} N at "
          f"{100 * contraction:g}% contraction")
    results = []
    for label, connector in (("listed length, 2000 N/m connector", 2000.0),
                             ("max_length, rigid connector", 0.0)):
        m = Muscle(preset=1, bladder_model=3, bladder_layers=16, connector_stiffness=connector)
        rest = LISTED_LENGTH if connector > 0 else m.get("max_length")
        length = rest * (1.0 - contraction)
        p, f0, fmax = pressure_for(m, target, length)
        if p is None:
            print(f"  {label}: rest {1e3 * rest:.2f} mm, length {1e3 * length:.2f} mm: no pressure in "
                  f"0-1000 kPa gives {target:g} N (force {f0:.1f} N at 0 kPa, {fmax:.1f} N at 1000 kPa)")
            sys.exit(1)
        check = m.force(p, length)
        print(f"  {label}: rest {1e3 * rest:.2f} mm, length {1e3 * length:.2f} mm -> "
              f"pressure {p / 1e3:.1f} kPa (force there {check:.3f} N, "
              f"effective pressure {m.get('effective_pressure') / 1e3:.1f} kPa)")
        assert abs(check - target) < 0.01 * target, (check, target)
        results.append(p)
        m.close()
    assert all(0.0 < p < 1.0e6 for p in results)


if __name__ == "__main__":
    main()

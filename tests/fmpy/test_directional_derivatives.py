"""fmi2GetDirectionalDerivative through FMPy against central differences of the FMU's own outputs,
at points across every effect of McKibbenMuscle (ideal sleeve; thin and thick wall in contact and
free; continuum wall; pre-strain; friction mid-presliding; connector spring; the pressure solver),
McKibbenJoint, KnittedMuscle (shapes, friction, bladder walls, section 1.4's bag), FreeBladder and
PassThrough. `stiffness` is itself dF/dL: its partials are second derivatives of the force."""

import pytest

from conftest import Slave

OUTPUTS = [
    "force", "volume", "effective_pressure", "friction_force", "threshold_pressure", "stretch_axial",
    "stretch_hoop", "stretch_radial", "stress_axial", "stress_hoop", "stress_radial", "contraction",
    "stiffness",
]
INPUTS = ["pressure", "length"]

# (parameters, points (pressure Pa, length as a fraction of the min..max range)).
CASES = {
    "ideal A": (dict(preset=1), [(3e5, 0.8), (-2e4, 0.7)]),
    "thin wall A (free, contact)": (dict(preset=1, bladder_model=1), [(5e4, 0.95), (4e5, 0.4)]),
    "thick wall A, 8 layers": (dict(preset=1, bladder_model=2, bladder_layers=8), [(4e5, 0.5), (1e5, 0.9)]),
    "exact wall A, 16 nodes (free, contact)": (
        dict(preset=1, bladder_model=3, bladder_layers=16), [(5e4, 0.95), (4e5, 0.5)],
    ),
    "dissertation's continuum A, 6 nodes (free, contact)": (
        dict(preset=1, bladder_model=6, bladder_layers=6), [(5e4, 0.95), (4e5, 0.5)],
    ),
    "dissertation's thin wall A (free, contact)": (dict(preset=1, bladder_model=4), [(5e4, 0.95), (4e5, 0.4)]),
    "pre-strained C, thin wall": (dict(preset=3, bladder_model=1), [(2e5, 0.6), (6e5, 0.8)]),
    "B, thick wall, friction": (
        dict(preset=2, bladder_model=2, bladder_layers=4, friction=True),
        [(3e5, 0.6), (5e5, 0.75)],
    ),
    "D, thin wall, connector 5e4 N/m": (
        dict(preset=4, bladder_model=1, connector_stiffness=5e4),
        [(3e5, 0.6), (5e5, 0.7)],
    ),
    "D, ideal, friction and connector": (
        dict(preset=4, friction=True, connector_stiffness=2e4),
        [(4e5, 0.7)],
    ),
    "B, exact wall, friction": (
        dict(preset=2, bladder_model=3, bladder_layers=6, friction=True),
        [(1e5, 0.6), (5e5, 0.8)],
    ),
    "C, exact wall, friction and connector": (
        dict(preset=3, bladder_model=3, bladder_layers=16, friction=True, connector_stiffness=5e4),
        [(2e5, 0.6), (6e5, 0.8)],
    ),
}


def directional(s, unknowns, knowns, seed):
    vr = lambda names: [s.vars[n].valueReference for n in names]
    return list(s.fmu.getDirectionalDerivative(vr(unknowns), vr(knowns), seed))


@pytest.mark.parametrize("case", CASES)
def test_muscle_partials_match_central_differences(case):
    parameters, points = CASES[case]
    s = Slave("McKibbenMuscle", **parameters)
    assert s.md.coSimulation.providesDirectionalDerivative
    lo, hi = s.get("min_length", "max_length")
    try:
        for pressure, frac in points:
            length = lo + frac * (hi - lo)
            # Friction history sits 30 um behind (mid-presliding at 100 um): off the reversal kink.
            s.step(pressure=pressure, length=length - 3e-5)
            base = dict(pressure=pressure, length=length)
            for j, name in enumerate(INPUTS):
                h = 1e-6 * abs(base[name]) + (1e-3 if name == "pressure" else 0.0)
                seed = [1.0 if k == j else 0.0 for k in range(2)]
                s.set(**base)
                exact = directional(s, OUTPUTS, INPUTS, seed)
                up = s.at(*OUTPUTS, **{**base, name: base[name] + h})
                down = s.at(*OUTPUTS, **{**base, name: base[name] - h})
                for out, e, a, b in zip(OUTPUTS, exact, up, down):
                    central = (a - b) / (2 * h)
                    scale = max(abs(e), abs(central))
                    assert abs(e - central) <= 1e-5 * scale + 1e-12, (
                        f"{case} P={pressure} L={length}: d{out}/d{name} exact {e} central {central}"
                    )
    finally:
        s.close()


@pytest.mark.parametrize(
    "parameters",
    [dict(preset=2, bladder_model=1), dict(preset=4, bladder_model=2, bladder_layers=4, connector_stiffness=5e4)],
    ids=["B thin wall", "D thick wall + connector"],
)
def test_target_pressure_partials_match_central_differences(parameters):
    """target_pressure solves F(P, L) = target_force: dP/dF = 1/F_P, dP/dL = -F_L/F_P."""
    # The solver inverts the rigid braid's signed force; at these lengths the bladder muscles
    # are past their free contraction, so their forces are negative.
    s = Slave("McKibbenMuscle", pressure_solver=True, max_pressure=8e5, signed_force=True,
              strand_rigidity=1e12, **parameters)
    lo, hi = s.get("min_length", "max_length")
    knowns = ["pressure", "length", "target_force"]
    try:
        for frac in [0.3, 0.5]:
            length = lo + frac * (hi - lo)
            # A force the muscle reaches at 4 bar: the solver must find that pressure.
            force = s.at("force", pressure=4e5, length=length)
            base = dict(pressure=2e5, length=length, target_force=force)
            s.set(**base)
            assert not s.get("target_force_saturated")
            assert s.get("target_pressure") == pytest.approx(4e5, rel=1e-9)
            for j, name in enumerate(knowns):
                h = 1e-6 * abs(base[name]) + (1e-3 if name == "pressure" else 0.0)
                s.set(**base)
                exact = directional(s, ["target_pressure"], knowns, [1.0 if k == j else 0.0 for k in range(3)])[0]
                up = s.at("target_pressure", **{**base, name: base[name] + h})
                down = s.at("target_pressure", **{**base, name: base[name] - h})
                central = (up - down) / (2 * h)
                # Absolute slack: the solver meets the force to its tolerance (1e-12 relative).
                assert abs(exact - central) <= 1e-5 * max(abs(exact), abs(central)) + 1e-4, (
                    f"{parameters} F={force}: dtarget_pressure/d{name} exact {exact} central {central}"
                )
                assert (exact != 0.0) == (name != "pressure")
    finally:
        s.close()


def test_seed_combines_linearly_and_pass_through_is_identity():
    s = Slave("McKibbenMuscle", preset=1, bladder_model=1)
    try:
        s.set(pressure=3e5, length=0.08)
        dp, dl = directional(s, ["force"], INPUTS, [1.0, 0.0])[0], directional(s, ["force"], INPUTS, [0.0, 1.0])[0]
        both = directional(s, ["force"], INPUTS, [2.0, -3.0])[0]
        assert both == pytest.approx(2 * dp - 3 * dl, rel=1e-14)
    finally:
        s.close()
    p = Slave("PassThrough")
    try:
        assert directional(p, ["y"], ["u"], [2.5]) == [2.5]
    finally:
        p.close()


FREE_BLADDER_OUTPUTS = [
    "inner_diameter", "outer_diameter", "volume", "compliance", "stretch_axial", "stretch_hoop",
    "stretch_radial", "stress_axial", "stress_hoop", "force", "ballooning_pressure",
]
# (parameters, points (axial stretch, pressure as a fraction of the ballooning pressure)): muscle
# D's thin tube (the defaults) and muscle A's thick tube (Table 2.1); relaxed, pre-strained,
# compressed, near ballooning, under vacuum.
FREE_BLADDER_CASES = {
    "D tube": (dict(), [(1.0, 0.5), (1.4, 0.99), (0.7, -0.5), (2.0, 0.0)]),
    "A tube": (
        dict(bladder_length=0.1005, bladder_inner_diameter=1.6e-3, bladder_thickness=1.6e-3),
        [(1.0, 0.5), (1.3, 0.99), (0.8, -0.1)],
    ),
}


@pytest.mark.parametrize("case", FREE_BLADDER_CASES)
def test_free_bladder_partials_match_central_differences(case):
    """FreeBladder: every Real output by both inputs (the implicit function theorem on eq. 2.18),
    in both interfaces' flags, within the same 1e-5 as the muscles."""
    parameters, points = FREE_BLADDER_CASES[case]
    s = Slave("FreeBladder", **parameters)
    assert s.md.coSimulation.providesDirectionalDerivative
    assert s.md.modelExchange.providesDirectionalDerivative
    l0 = float(parameters.get("bladder_length", s.vars["bladder_length"].start))
    try:
        for stretch, fraction in points:
            length = stretch * l0
            top = s.at("ballooning_pressure", pressure=0.0, length=length)
            base = dict(pressure=fraction * top, length=length)
            steps = dict(pressure=1e-5 * (1.0 - abs(fraction)) * top + 1e-3, length=1e-7 * l0)
            for j, name in enumerate(INPUTS):
                h = steps[name]
                s.set(**base)
                assert not s.get("input_clamped")
                exact = directional(s, FREE_BLADDER_OUTPUTS, INPUTS, [1.0 if k == j else 0.0 for k in range(2)])
                up = s.at(*FREE_BLADDER_OUTPUTS, **{**base, name: base[name] + h})
                down = s.at(*FREE_BLADDER_OUTPUTS, **{**base, name: base[name] - h})
                for out, e, a, b in zip(FREE_BLADDER_OUTPUTS, exact, up, down):
                    central = (a - b) / (2 * h)
                    # Absolute slack for the difference's rounding: 1e-12 of the output's size
                    # (at least 1e5 Pa for a stress, whose hoop part vanishes at zero pressure) per
                    # the step.
                    size = max(abs(a), abs(b), 1e5 if out.startswith("stress") else 0.0)
                    slack = 1e-12 * size / h
                    assert abs(e - central) <= 1e-5 * max(abs(e), abs(central)) + slack, (
                        f"{case} lambda={stretch} P={base['pressure']}: d{out}/d{name} exact {e} central {central}"
                    )
    finally:
        s.close()


JOINT_OUTPUTS = ["jointTorque", "flexor_force", "extensor_force", "flexor_pressure", "extensor_pressure",
                 "flexor_length", "extensor_length"]
JOINT_INPUTS = ["actuatorInput", "jointPosition", "jointVelocity"]


@pytest.mark.parametrize(
    "parameters",
    [
        dict(),
        dict(bladder_model=2, bladder_layers=8),
        dict(bladder_model=1, friction=True),
        dict(bladder_model=1, command_mode=1),
        dict(bladder_model=3, bladder_layers=16, friction=True),
    ],
    ids=["ideal", "thick wall", "thin wall + friction", "thin wall, torque command", "exact wall + friction"],
)
def test_joint_partials_match_central_differences(parameters):
    s = Slave("McKibbenJoint", **parameters)
    try:
        # Inside the pressure range (no saturation) and with friction mid-presliding.
        torque = parameters.get("command_mode") == 1
        # And past max_position, the extensor on its stretching strands (2% of b past its reach).
        on_strands = s.get("max_position") + 0.02 * 0.1113 / s.get("moment_arm")
        points = [(0.3, 0.05), (-0.5, -0.1), (0.3, on_strands)] if torque else [
            (1e5, 0.05), (-2e5, -0.1), (1e5, on_strands)]
        for u, q in points:
            # Stepped at another command: on the strands the braid stays where they took over,
            # so a step at the same pressures would leave the friction history at a reversal.
            s.step(actuatorInput=0.9 * u, jointPosition=q + 1e-3)
            base = dict(actuatorInput=u, jointPosition=q, jointVelocity=0.0)
            s.set(**base)
            for j, name in enumerate(JOINT_INPUTS):
                h = (1e-6 if torque else 1.0) if name == "actuatorInput" else 1e-7
                seed = [1.0 if k == j else 0.0 for k in range(3)]
                s.set(**base)
                exact = directional(s, JOINT_OUTPUTS, JOINT_INPUTS, seed)
                up = s.at(*JOINT_OUTPUTS, **{**base, name: base[name] + h})
                down = s.at(*JOINT_OUTPUTS, **{**base, name: base[name] - h})
                for out, e, a, b in zip(JOINT_OUTPUTS, exact, up, down):
                    central = (a - b) / (2 * h)
                    # Absolute slack: the torque solver meets the command to rounding (1e-16 N m / h).
                    assert abs(e - central) <= 1e-5 * max(abs(e), abs(central)) + 1e-8, (
                        f"{parameters} u={u} q={q}: d{out}/d{name} exact {e} central {central}"
                    )
    finally:
        s.close()


KNITTED_OUTPUTS = ["force", "volume", "effective_pressure", "friction_force", "max_radius", "stiffness"]
KNITTED_CASES = {
    "ideal": (dict(shape_model=0), [1.4e4, 5e4]),
    "tubular, friction": (dict(shape_model=1, friction=True), [1.4e4, 5e4]),
    "non-cylindrical table, friction": (dict(shape_model=2, friction=True), [1.4e4, 5e4]),
    "Fig. 1.16 tubular, thin wall (free, contact)": (dict(preset=2, shape_model=1, bladder_model=1), [2e4, 5.5e5]),
    "Fig. 1.16 ideal, thick wall, friction": (
        dict(preset=2, shape_model=0, bladder_model=2, bladder_layers=6, friction=True), [1.5e5, 5.5e5],
    ),
    "Fig. 1.16 tubular, exact wall": (
        dict(preset=2, shape_model=1, bladder_model=3, bladder_layers=6), [2e4, 5.5e5],
    ),
    "prototype in its 85 mm bag, friction": (
        dict(preset=1, shape_model=0, bag_diameter=0.085, friction=True), [1.4e4, 5e4],
    ),
    "prototype, tubular, stretching bag (E t = 1e4 N/m)": (
        dict(preset=1, shape_model=1, bag_diameter=0.085, bag_membrane_stiffness=1e4), [1.4e4, 5e4],
    ),
}


@pytest.mark.parametrize("case", KNITTED_CASES)
def test_knitted_partials_match_central_differences(case):
    """KnittedMuscle: every output against central differences (the bag binds at 0.4 of the range)."""
    parameters, pressures = KNITTED_CASES[case]
    s = Slave("KnittedMuscle", **parameters)
    assert s.md.coSimulation.providesDirectionalDerivative
    assert s.md.modelExchange.providesDirectionalDerivative
    outputs = KNITTED_OUTPUTS
    lo, hi = s.get("min_length", "max_length")
    try:
        # 1.02: past max_length, on the stretching yarn.
        for frac in [0.4, 0.8, 1.02]:
            length = lo + frac * (hi - lo)
            for pressure in pressures:
                # At another pressure: on the yarn the knit stays where the yarn took over, so a
                # step at the same pressure would leave the friction history at a reversal.
                s.step(pressure=0.99 * pressure, length=length - 3e-5)
                base = dict(pressure=pressure, length=length)
                for j, name in enumerate(INPUTS):
                    h = 1e-6 * abs(base[name]) + (1e-3 if name == "pressure" else 0.0)
                    s.set(**base)
                    exact = directional(s, outputs, INPUTS, [1.0 if k == j else 0.0 for k in range(2)])
                    up = s.at(*outputs, **{**base, name: base[name] + h})
                    down = s.at(*outputs, **{**base, name: base[name] - h})
                    for out, e, a, b in zip(outputs, exact, up, down):
                        central = (a - b) / (2 * h)
                        assert abs(e - central) <= 1e-5 * max(abs(e), abs(central)) + 1e-12, (
                            f"{case} P={pressure} L={length}: d{out}/d{name} exact {e} central {central}"
                        )
    finally:
        s.close()

"""FMI 3.0 Co-Simulation event mode, through ctypes: the motor's stepping schedule switches are
time events at k * step_period. With earlyReturnAllowed, fmi3DoStep ends exactly at each switch;
without, it steps through and raises eventHandlingNeeded at the step's end. Either way the results
at the communication points are those of a run without event mode (the independent truth: the same
library stepped over the same communication points with event mode off)."""

import ctypes
import math
import zipfile
from ctypes import byref, c_bool, c_char_p, c_double, c_int, c_size_t, c_uint, c_void_p

import pytest
from fmpy import read_model_description

from actuator_fmus.paths import FMI3_DIR

OK, ERROR = 0, 3
LOG = ctypes.CFUNCTYPE(None, c_void_p, c_int, c_char_p, c_char_p)
OUTPUTS = ["rotor_angle", "rotor_speed", "torque", "onion_angle"]
PERIOD = 1e-4  # step_period (s): the schedule switches at k * PERIOD
H = 3e-5  # communication step (s): not a divisor of PERIOD, so switches fall inside steps
STEPS = 34  # to 1.02 ms: ten switches, three of them (k * 0.3 ms) on a communication point


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    out = tmp_path_factory.mktemp("fmi3_events")
    with zipfile.ZipFile(FMI3_DIR / "MultiferroicMotor.fmu") as z:
        path = z.extract("binaries/x86_64-linux/MultiferroicMotor.so", out)
    dll = ctypes.CDLL(path)
    dll.fmi3InstantiateCoSimulation.restype = c_void_p
    return dll


class Slave:
    """One FMI 3.0 Co-Simulation instance with a recording logger."""

    def __init__(self, lib, model, event_mode_used, early_return_allowed):
        self.lib = lib
        self.md = read_model_description(str(FMI3_DIR / f"{model}.fmu"))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.messages = []
        self.log = LOG(lambda env, status, category, message: self.messages.append(message.decode()))
        self.c = c_void_p(lib.fmi3InstantiateCoSimulation(
            b"x", self.md.instantiationToken.encode(), None, False, False, event_mode_used,
            early_return_allowed, None, c_size_t(0), None, self.log, None))
        assert self.c.value, self.messages

    def __call__(self, function, *args):
        return getattr(self.lib, function)(self.c, *args)

    def initialize(self, schedule=True):
        assert self("fmi3EnterInitializationMode", False, c_double(0), c_double(0.0), False, c_double(0)) == OK
        if schedule:
            vr = (c_uint * 1)(self.vr["schedule"])
            assert self("fmi3SetInt64", vr, c_size_t(1), (ctypes.c_int64 * 1)(1), c_size_t(1)) == OK
            vr = (c_uint * 1)(self.vr["step_period"])
            assert self("fmi3SetFloat64", vr, c_size_t(1), (c_double * 1)(PERIOD), c_size_t(1)) == OK
        assert self("fmi3ExitInitializationMode") == OK

    def get(self, names):
        vrs = (c_uint * len(names))(*[self.vr[k] for k in names])
        x = (c_double * len(names))()
        assert self("fmi3GetFloat64", vrs, c_size_t(len(names)), x, c_size_t(len(names))) == OK
        return list(x)

    def do_step(self, t, h):
        event, terminate, early, last = c_bool(), c_bool(), c_bool(), c_double()
        status = self("fmi3DoStep", c_double(t), c_double(h), True, byref(event), byref(terminate),
                      byref(early), byref(last))
        assert status == OK, self.messages
        return event.value, early.value, last.value

    def handle_event(self, enter=True):
        """Event Mode (entered, or where initialization left it) and back to Step Mode: returns
        the next event time the FMU gives."""
        if enter:
            assert self("fmi3EnterEventMode") == OK, self.messages
        flags = [c_bool() for _ in range(5)]
        next_time = c_double()
        assert self("fmi3UpdateDiscreteStates", *map(byref, flags), byref(next_time)) == OK
        update, terminate, nominals, values, defined = (f.value for f in flags)
        assert not (update or terminate or nominals or values)
        assert self("fmi3EnterStepMode") == OK
        return next_time.value if defined else None

    def free(self):
        self.lib.fmi3FreeInstance(self.c)


def grid(k):
    return k * H


def switch_index(t):
    """The number of switches up to `t`, a switch within rounding of `t` included."""
    j = round(t / PERIOD)
    return j if abs(t / PERIOD - j) < 1e-9 else math.floor(t / PERIOD)


def reference_run(lib):
    """Event mode off: the communication points and the outputs there."""
    s = Slave(lib, "MultiferroicMotor", False, False)
    s.initialize()
    t, rows = 0.0, []
    for k in range(STEPS):
        event, early, t = s.do_step(t, grid(k + 1) - t)
        assert not (event or early)
        rows.append((t, s.get(OUTPUTS)))
    s.free()
    return rows


def test_early_return_lands_on_every_switch_and_keeps_the_results(lib):
    reference = reference_run(lib)
    s = Slave(lib, "MultiferroicMotor", True, True)
    s.initialize()
    # eventModeUsed: the instance starts in Event Mode.
    flags, last = [c_bool() for _ in range(3)], c_double()
    assert s("fmi3DoStep", c_double(0), c_double(H), True, *map(byref, flags), byref(last)) == ERROR
    assert s.handle_event(enter=False) == PERIOD
    t, switches, worst = 0.0, [], {name: 0.0 for name in OUTPUTS}
    # Each output's differences relative to its largest magnitude in the run.
    scales = [max(abs(row[1][i]) for row in reference) for i in range(len(OUTPUTS))]
    for k in range(STEPS):
        while True:
            event, early, t = s.do_step(t, grid(k + 1) - t)
            if event:
                # Early, or a switch on the communication point (every third, at 3e-4 s).
                assert early or t == grid(k + 1)
                switches.append(t)
                expected = len(switches) * PERIOD
                assert abs(t - expected) <= 1e-15 * expected, (t, expected)
                assert s.handle_event() == (len(switches) + 1) * PERIOD
            if not early:
                break
        assert t == reference[k][0]
        for i, (name, got, want) in enumerate(zip(OUTPUTS, s.get(OUTPUTS), reference[k][1])):
            worst[name] = max(worst[name], abs(got - want) / scales[i])
    assert len(switches) == int(grid(STEPS) / PERIOD)
    s.free()
    # Splitting a step at the switch changes the integrator's substeps and so the rounding; the
    # switch itself is not moved. The bound is far above the measured differences (docs/fmi3.md)
    # and far below the integrator's tolerance (1e-6 rad).
    print("largest difference at the communication points, relative to the output's range:", worst)
    for name, difference in worst.items():
        assert difference <= 1e-11, (name, difference)


def test_without_early_return_the_steps_run_through_and_flag_the_switch(lib):
    reference = reference_run(lib)
    s = Slave(lib, "MultiferroicMotor", True, False)
    s.initialize()
    assert s.handle_event(enter=False) == PERIOD
    t, flagged = 0.0, []
    for k in range(STEPS):
        start = t
        event, early, t = s.do_step(t, grid(k + 1) - t)
        assert not early
        assert t == reference[k][0]
        # The same steps as without event mode: bit for bit.
        assert s.get(OUTPUTS) == reference[k][1]
        # A switch j * PERIOD in (start, t], the ends within rounding.
        switch_inside = switch_index(t) > switch_index(start)
        assert event == switch_inside, (start, t)
        if event:
            flagged.append(k)
            assert s.handle_event() == (switch_index(t) + 1) * PERIOD
    assert len(flagged) == int(grid(STEPS) / PERIOD)
    s.free()


def test_without_the_schedule_or_events_nothing_is_flagged(lib):
    for model, schedule in [("MultiferroicMotor", False), ("McKibbenMuscle", False)]:
        s = Slave(lib, model, True, True)
        s.initialize(schedule=schedule)
        assert s.handle_event(enter=False) is None
        t = 0.0
        for k in range(10):
            event, early, t = s.do_step(t, grid(k + 1) - t)
            assert not (event or early)
        s.free()


def test_step_mode_calls_out_of_place_are_logged_errors(lib):
    s = Slave(lib, "MultiferroicMotor", False, False)
    s.initialize()
    assert s("fmi3EnterStepMode") == ERROR
    assert "no event mode" in s.messages[-1]
    assert s("fmi3EnterEventMode") == ERROR
    s.free()
    s = Slave(lib, "MultiferroicMotor", True, True)
    s.initialize()
    assert s.handle_event(enter=False) == PERIOD
    assert s("fmi3EnterStepMode") == ERROR  # already in Step Mode
    assert s("fmi3Terminate") == OK
    s.free()


def test_fmpy_simulate_fmu_lands_on_the_switches(lib):
    """FMPy's own Co-Simulation loop (an independent importer) with event mode and early return:
    a result row at every switch, and the communication points as without event mode."""
    from fmpy import simulate_fmu

    def run(events):
        return simulate_fmu(str(FMI3_DIR / "MultiferroicMotor.fmu"), stop_time=STEPS * H, output_interval=H,
                            start_values={"schedule": 1, "step_period": PERIOD}, output=OUTPUTS,
                            use_event_mode=events, early_return_allowed=events)

    plain, events = run(False), run(True)
    switches = [j * PERIOD for j in range(1, switch_index(STEPS * H) + 1)]
    for switch in switches:
        assert min(abs(t - switch) for t in events["time"]) <= 1e-15 * switch, switch
    on_grid = {t: row for t, row in zip(events["time"], events)}
    for row in plain:
        other = on_grid[row["time"]]  # the last row at that time (after the event)
        for name in OUTPUTS:
            scale = max(abs(plain[name]).max(), 1e-300)
            assert abs(other[name] - row[name]) <= 1e-11 * scale, (row["time"], name)


def test_pulley_joint_returns_at_its_segment_boundaries():
    """PulleyJoint's other time events, the reference trajectory's segment boundaries k *
    segment_time (1 s), are reported the same way; its fixed substeps make the split exact."""
    from fmpy import simulate_fmu

    path = str(FMI3_DIR / "PulleyJoint.fmu")
    outputs = ["flexor_length", "extensor_length", "flexor_pressure", "extensor_pressure"]
    plain = simulate_fmu(path, stop_time=5.0, output_interval=0.07, output=outputs)
    events = simulate_fmu(path, stop_time=5.0, output_interval=0.07, output=outputs,
                          use_event_mode=True, early_return_allowed=True)
    assert sorted(set(events["time"]) - set(plain["time"])) == [1.0, 2.0, 3.0, 4.0]
    on_grid = {t: row for t, row in zip(events["time"], events)}
    for row in plain:
        assert [on_grid[row["time"]][n] for n in outputs] == [row[n] for n in outputs], row["time"]


def test_an_fmu_state_saved_at_a_switch_restores_in_event_mode(lib):
    s = Slave(lib, "MultiferroicMotor", True, True)
    s.initialize()
    assert s.handle_event(enter=False) == PERIOD
    event, early, t = s.do_step(0.0, 1.5 * PERIOD)
    assert early and t == PERIOD
    assert s("fmi3EnterEventMode") == OK
    state = c_void_p()
    assert s("fmi3GetFMUState", byref(state)) == OK
    before = s.get(OUTPUTS)
    assert s.handle_event(enter=False) == 2 * PERIOD
    s.do_step(t, 0.5 * PERIOD)
    # Back at the switch, in Event Mode: the same outputs, and stepping on needs Step Mode.
    assert s("fmi3SetFMUState", state) == OK, s.messages
    assert s.get(OUTPUTS) == before
    assert s.handle_event(enter=False) == 2 * PERIOD
    assert s.do_step(PERIOD, 0.5 * PERIOD)[2] == 1.5 * PERIOD
    assert s("fmi3FreeFMUState", byref(state)) == OK
    s.free()

//! The stepping strain schedule of section 3.2.2: the principal tension turns by `step_angle` every
//! `step_period`. Uniaxial stress is symmetric under 180 degrees, so with 60-degree steps the new
//! magnetoelastic minima lie at +60 and -120 degrees from the old one, and the onion state's
//! downhill move (+60) is unique.

/// Times within this fraction of a period before a switch count as after it, so that a time that
/// is a sum of many communication steps lands in the same step as the exact switching time.
const SWITCH_SNAP: f64 = 1e-9;

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SteppingSchedule {
    /// Direction of the principal tension during the first period (rad).
    pub initial_direction: f64,
    /// Increment of the direction at each switch (rad); default 60 degrees.
    pub step_angle: f64,
    /// Time between switches (s).
    pub step_period: f64,
    /// `sigma11 - sigma22` throughout (Pa).
    pub stress_amplitude: f64,
}

impl SteppingSchedule {
    pub fn new(
        initial_direction: f64,
        step_angle: f64,
        step_period: f64,
        stress_amplitude: f64,
    ) -> Result<Self, String> {
        if !initial_direction.is_finite() || initial_direction.abs() > 1e6 {
            return Err(format!(
                "initial_direction must be finite and within 1e6 rad, got {initial_direction}"
            ));
        }
        if !step_angle.is_finite() || step_angle.abs() > 1e3 {
            return Err(format!(
                "step_angle must be finite and within 1e3 rad, got {step_angle}"
            ));
        }
        if !(step_period.is_finite() && step_period > 0.0) {
            return Err(format!(
                "step_period must be positive and finite, got {step_period} s"
            ));
        }
        if !stress_amplitude.is_finite() || stress_amplitude.abs() > super::MAX_STRESS {
            return Err(format!(
                "stress_amplitude must be finite and within {} Pa, got {stress_amplitude}",
                super::MAX_STRESS
            ));
        }
        Ok(Self {
            initial_direction,
            step_angle,
            step_period,
            stress_amplitude,
        })
    }

    /// Whether [`Self::new`] accepts these fields, in one test (it says why not).
    #[inline]
    pub fn is_valid(&self) -> bool {
        (self.initial_direction.abs() <= 1e6)
            & (self.step_angle.abs() <= 1e3)
            & (self.step_period > 0.0)
            & (self.step_period < f64::INFINITY)
            & (self.stress_amplitude.abs() <= super::MAX_STRESS)
    }

    /// Index of the period containing `time` (0 before the first switch, and for negative time).
    pub fn step_index(&self, time: f64) -> f64 {
        let k = floor(time / self.step_period + SWITCH_SNAP);
        if k.is_finite() {
            k.max(0.0)
        } else {
            0.0
        }
    }

    /// Direction of the principal tension at `time` (rad), right-continuous at the switches.
    pub fn direction(&self, time: f64) -> f64 {
        self.initial_direction + self.step_index(time) * self.step_angle
    }

    /// The first switching time strictly after `time`, always later than `time` by a
    /// representable amount.
    pub fn next_switch_after(&self, time: f64) -> f64 {
        let next = (self.step_index(time) + 1.0) * self.step_period;
        if next > time {
            next
        } else {
            time + self.step_period.max(time.abs() * 4.0 * f64::EPSILON)
        }
    }
}

/// `x.floor()`, inline where the integer conversion is exact: without SSE4.1 in the baseline
/// target `floor` is a library call, and each motor step takes about five.
#[inline]
fn floor(x: f64) -> f64 {
    if x.abs() < 4e15 {
        let t = x as i64 as f64;
        if t > x {
            t - 1.0
        } else {
            t
        }
    } else {
        x.floor()
    }
}

/// The built-in schedule, switched on or off. Deliberately not an `Option<SteppingSchedule>`: a
/// `None` leaves the four payload floats uninitialised, and optimized code loaded `step_period`
/// from it and branched on its `floor` before testing the tag (valgrind: "conditional jump
/// depends on uninitialised value"). Here every field is always defined, whichever the switch.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ScheduleSwitch {
    on: bool,
    schedule: SteppingSchedule,
}

impl ScheduleSwitch {
    /// No schedule: the fixed `strain_direction` and `stress` drive the ring.
    pub const OFF: Self = Self {
        on: false,
        schedule: SteppingSchedule {
            initial_direction: 0.0,
            step_angle: 0.0,
            step_period: 1.0,
            stress_amplitude: 0.0,
        },
    };

    /// `schedule`, used only when `on`.
    pub fn new(on: bool, schedule: SteppingSchedule) -> Self {
        Self { on, schedule }
    }

    pub fn on(schedule: SteppingSchedule) -> Self {
        Self::new(true, schedule)
    }

    /// The schedule if it is switched on.
    pub fn get(&self) -> Option<&SteppingSchedule> {
        self.on.then_some(&self.schedule)
    }
}

#[cfg(test)]
mod tests {
    use super::SteppingSchedule;

    #[test]
    fn is_valid_agrees_with_new() {
        let good = SteppingSchedule::new(0.1, 1.0, 1e-4, 2e8).unwrap();
        assert!(good.is_valid());
        for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY, 2e6, -2e6] {
            for i in 0..4 {
                let mut f = [0.1, 1.0, 1e-4, 2e8];
                f[i] = bad;
                let s = SteppingSchedule {
                    initial_direction: f[0],
                    step_angle: f[1],
                    step_period: f[2],
                    stress_amplitude: f[3],
                };
                let new = SteppingSchedule::new(f[0], f[1], f[2], f[3]);
                assert_eq!(s.is_valid(), new.is_ok(), "{f:?}");
            }
        }
        for period in [0.0, -1e-4, 1e300] {
            let s = SteppingSchedule {
                step_period: period,
                ..good
            };
            assert_eq!(
                s.is_valid(),
                SteppingSchedule::new(0.1, 1.0, period, 2e8).is_ok()
            );
        }
    }
}

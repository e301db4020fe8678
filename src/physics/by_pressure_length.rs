//! The one shape of the exact first partials of a pressure-driven actuator's outputs with respect
//! to its gauge pressure `P` and its length `L`: the bladder (eq. 2.8-2.19), the McKibben muscle
//! (eq. 2.3, 2.4, its connector) and the knitted muscle (eq. 1.8, 1.21) each write the fields they
//! have and leave the others zero.

/// `[d/dP, d/dL]` of each output, per Pa and per m.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ByPressureLength {
    /// Tension `F`, N/Pa and N/m.
    pub force: [f64; 2],
    /// Contact pressure `P_eff` (eq. 2.12, 2.19), 1 and Pa/m; zero when free.
    pub effective_pressure: [f64; 2],
    /// Friction's share of the force (eq. 2.4, 1.21), N/Pa and N/m.
    pub friction_force: [f64; 2],
    /// Gas volume, m^3/Pa and m^2.
    pub volume: [f64; 2],
    /// Threshold pressure `c/a` at the contact diameter, 1 and Pa/m (its `P`-slope is zero).
    pub threshold_pressure: [f64; 2],
    /// Stretches of the bladder's innermost layer (eq. 2.8a-c), 1/Pa and 1/m.
    pub stretch_axial: [f64; 2],
    pub stretch_hoop: [f64; 2],
    pub stretch_radial: [f64; 2],
    /// True stresses of the bladder's innermost layer (eq. 2.9a-b; radial `-P`), 1 and Pa/m.
    pub stress_axial: [f64; 2],
    pub stress_hoop: [f64; 2],
    pub stress_radial: [f64; 2],
    /// The knitted sleeve's largest radius, m/Pa and 1.
    pub max_radius: [f64; 2],
    /// Stiffness `dF/dL`, N/(m Pa) and N/m^2: a second derivative of the force, `None` where it
    /// was not taken (through a bladder it costs a second-order pass).
    pub stiffness: Option<[f64; 2]>,
}

impl ByPressureLength {
    /// The first-order rows (all but the stiffness), in the order of the fields.
    pub fn rows(&self) -> [[f64; 2]; 12] {
        [
            self.force,
            self.effective_pressure,
            self.friction_force,
            self.volume,
            self.threshold_pressure,
            self.stretch_axial,
            self.stretch_hoop,
            self.stretch_radial,
            self.stress_axial,
            self.stress_hoop,
            self.stress_radial,
            self.max_radius,
        ]
    }

    /// [`Self::rows`], mutable: for a change of variables that applies to every row (the
    /// connector's `L(P, reported)`, the strands' stretch).
    pub fn rows_mut(&mut self) -> [&mut [f64; 2]; 12] {
        [
            &mut self.force,
            &mut self.effective_pressure,
            &mut self.friction_force,
            &mut self.volume,
            &mut self.threshold_pressure,
            &mut self.stretch_axial,
            &mut self.stretch_hoop,
            &mut self.stretch_radial,
            &mut self.stress_axial,
            &mut self.stress_hoop,
            &mut self.stress_radial,
            &mut self.max_radius,
        ]
    }

    /// Every partial is finite (the stiffness's too, where taken).
    pub fn is_finite(&self) -> bool {
        self.rows()
            .iter()
            .chain(&self.stiffness)
            .flatten()
            .all(|x| x.is_finite())
    }
}

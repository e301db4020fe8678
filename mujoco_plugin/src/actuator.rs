//! One MuJoCo actuator driven by one FMU instance, and its history in MuJoCo's `plugin_state`.
//!
//! `plugin_state` of an instance: `[started, fmu_time, byte_count, packed bytes...]`, the
//! serialized FMU state (fmi2SerializeFMUstate) packed 6 bytes per mjtNum as an exact integer
//! below 2^48, so that every word is an ordinary finite number whatever MuJoCo or a user does with
//! it (copies, mj_getState, text files). `started = 0` (after mj_resetData, or in a fresh mjData)
//! means: initialize the FMU at rest at the actuator's current length on the next evaluation.
//!
//! The instance writes its state after every step and keeps a copy (`shadow`); when
//! `plugin_state` differs from that copy at the next callback (mj_setState, mj_resetData,
//! mj_copyData, an edited state), the FMU continues from what `plugin_state` holds.

use crate::config::Config;
use crate::fmu::{Instance, Value, Variable};
use crate::layout::{MjData, MjModel, OBJ_ACTUATOR};
use crate::mujoco as mj;

const HEADER: usize = 3;
const BYTES_PER_WORD: usize = 6;

/// `plugin_state` words for `bytes` bytes of FMU state.
pub fn state_words(bytes: usize) -> usize {
    HEADER + bytes.div_ceil(BYTES_PER_WORD)
}

/// Bytes of FMU state that fit in `words`.
fn state_capacity(words: usize) -> usize {
    words.saturating_sub(HEADER) * BYTES_PER_WORD
}

pub struct Actuator {
    config: Config,
    instance: Instance,
    pub id: usize,
    pub name: String,
    instance_id: i32,
    time: f64,
    /// Value references of the mapped inputs, in the order of [`Actuator::input_values`].
    input_vrs: [u32; 3],
    input_count: usize,
    /// Serialization buffer (the state's capacity) and the words last written to plugin_state.
    bytes: Vec<u8>,
    shadow: Vec<f64>,
}

impl Actuator {
    /// The FMU state's size after initialization with the configured parameters, plus room for
    /// it to grow: how much `plugin_state` the instance asks MuJoCo for.
    pub fn probe_state_words(config: &Config) -> Result<usize, String> {
        if !config.carry_history {
            return Ok(HEADER);
        }
        let mut instance = Instance::new(config.fmu.clone(), "probe")?;
        let values: Vec<_> = config
            .parameters
            .iter()
            .map(|(v, x)| (v, x.clone()))
            .collect();
        instance.initialize(&values, false)?;
        let size = instance.save_to_vec()?.len();
        let capacity = config.state_bytes.unwrap_or(size + size / 2 + 64);
        Ok(state_words(capacity))
    }

    /// The actuator of plugin instance `instance`, its FMU instantiated and initialized.
    ///
    /// # Safety
    /// `m` is live.
    pub unsafe fn new(m: *const MjModel, instance_id: i32, config: Config) -> Result<Self, String> {
        let users: Vec<usize> = (0..mj::nu(m))
            .filter(|&i| mj::actuator_plugin(m, i) == instance_id)
            .collect();
        let id = match users.as_slice() {
            [id] => *id,
            [] => return Err("no actuator uses this plugin instance".into()),
            _ => {
                return Err(format!(
                    "{} actuators share one plugin instance; each needs its own FMU instance \
                     (one <plugin> per actuator)",
                    users.len()
                ))
            }
        };
        let name = {
            let p = mj::mj_id2name(m, OBJ_ACTUATOR, id as i32);
            if p.is_null() {
                format!("#{id}")
            } else {
                std::ffi::CStr::from_ptr(p).to_string_lossy().into_owned()
            }
        };
        let mut instance = Instance::new(config.fmu.clone(), &name)?;
        let values: Vec<_> = config
            .parameters
            .iter()
            .map(|(v, x)| (v, x.clone()))
            .collect();
        instance.initialize(&values, false)?;
        let mapped: Vec<&Variable> = [&config.length, &config.velocity, &config.ctrl]
            .into_iter()
            .flatten()
            .collect();
        let mut input_vrs = [0u32; 3];
        for (slot, v) in input_vrs.iter_mut().zip(&mapped) {
            *slot = v.vr;
        }
        let words = mj::state_span(m, instance_id).1;
        Ok(Self {
            input_count: mapped.len(),
            input_vrs,
            bytes: vec![0u8; state_capacity(words)],
            // Never equal to a written state (those hold no NaN): the first callback reads
            // plugin_state.
            shadow: vec![f64::NAN; words],
            config,
            instance,
            id,
            name,
            instance_id,
            time: 0.0,
        })
    }

    /// For a copied mjData whose history is not in plugin_state: continues from `source`'s FMU
    /// state, handed over as bytes (once per copy, not per step).
    pub unsafe fn adopt(
        &mut self,
        m: *const MjModel,
        d: *mut MjData,
        source: &mut Actuator,
    ) -> Result<(), String> {
        if self.config.carry_history {
            return Ok(());
        }
        let bytes = source.instance.save_to_vec()?;
        self.instance.restore(&bytes)?;
        self.time = source.time;
        let state = self.state(m, d);
        if state[0] != 0.0 {
            // Started: continue from the source's FMU. Not started: start at the first
            // evaluation, as the source will.
            self.shadow.copy_from_slice(state);
        }
        Ok(())
    }

    /// Forgets what this instance last wrote: the next callback continues from plugin_state (a
    /// copied mjData's state, for one).
    pub fn resync(&mut self) {
        self.shadow.fill(f64::NAN);
    }

    /// The mapped inputs: length (+ offset), velocity, control (clamped to ctrlrange if limited).
    unsafe fn input_values(&self, m: *const MjModel, d: *const MjData) -> [f64; 3] {
        let mut values = [0.0; 3];
        let mut n = 0;
        if self.config.length.is_some() {
            values[n] = mj::actuator_length(d, self.id) + self.config.length_offset;
            n += 1;
        }
        if self.config.velocity.is_some() {
            values[n] = mj::actuator_velocity(d, self.id);
            n += 1;
        }
        if self.config.ctrl.is_some() {
            let mut u = mj::ctrl(d, self.id);
            if let Some((lo, hi)) = mj::ctrl_range(m, self.id) {
                u = u.clamp(lo.min(hi), hi.max(lo));
            }
            values[n] = u;
        }
        values
    }

    unsafe fn set_inputs(&self, m: *const MjModel, d: *const MjData) -> Result<(), String> {
        let values = self.input_values(m, d);
        let n = self.input_count;
        if n == 0 {
            return Ok(());
        }
        if let Some(bad) = values[..n].iter().find(|x| !x.is_finite()) {
            return Err(format!("an input from MuJoCo is {bad}"));
        }
        self.instance.set_reals(&self.input_vrs[..n], &values[..n])
    }

    unsafe fn state<'a>(&self, m: *const MjModel, d: *mut MjData) -> &'a mut [f64] {
        let (adr, words) = mj::state_span(m, self.instance_id);
        std::slice::from_raw_parts_mut(mj::plugin_state(d).add(adr), words)
    }

    /// Brings the FMU to what plugin_state holds, if that changed since this instance wrote it.
    unsafe fn sync(&mut self, m: *const MjModel, d: *mut MjData) -> Result<(), String> {
        let state = self.state(m, d);
        let unchanged = state
            .iter()
            .zip(&self.shadow)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        if unchanged {
            return Ok(());
        }
        if state[0] == 0.0 {
            return self.start(m, d);
        }
        if !self.config.carry_history {
            return Err(
                "plugin_state was set to another moment (mj_setState?), but with \
                        history=\"fmu\" the FMU's history is not in plugin_state: use \
                        history=\"plugin_state\""
                    .into(),
            );
        }
        let count = state[2];
        let time = state[1];
        let valid = count.fract() == 0.0 && count > 0.0 && (count as usize) <= self.bytes.len();
        if !valid || !time.is_finite() {
            return Err(format!(
                "plugin_state holds no valid FMU state ({count} bytes at time {time})"
            ));
        }
        let count = count as usize;
        for (i, word) in state[HEADER..].iter().enumerate() {
            let bits = *word as u64;
            for k in 0..BYTES_PER_WORD {
                if let Some(b) = self.bytes.get_mut(i * BYTES_PER_WORD + k) {
                    *b = (bits >> (8 * k)) as u8;
                }
            }
        }
        self.instance
            .restore(&self.bytes[..count])
            .map_err(|e| format!("cannot continue from plugin_state: {e}"))?;
        self.time = time;
        self.shadow.copy_from_slice(state);
        Ok(())
    }

    /// Initializes the FMU at rest at the current inputs (time 0 of its own clock).
    unsafe fn start(&mut self, m: *const MjModel, d: *mut MjData) -> Result<(), String> {
        let inputs = self.input_values(m, d);
        let mapped = [
            &self.config.length,
            &self.config.velocity,
            &self.config.ctrl,
        ];
        let mut values: Vec<(&Variable, Value)> = self
            .config
            .parameters
            .iter()
            .map(|(v, x)| (v, x.clone()))
            .collect();
        for (variable, x) in mapped.into_iter().flatten().zip(inputs) {
            values.push((variable, Value::Real(x)));
        }
        self.instance.initialize(&values, true)?;
        self.time = 0.0;
        self.capture(m, d)
    }

    /// Writes the FMU's state into plugin_state (and the shadow copy).
    unsafe fn capture(&mut self, m: *const MjModel, d: *mut MjData) -> Result<(), String> {
        if !self.config.carry_history {
            let state = self.state(m, d);
            state[0] = 1.0;
            state[1] = self.time;
            self.shadow.copy_from_slice(state);
            return Ok(());
        }
        let count = self.instance.save(&mut self.bytes)?;
        let state = self.state(m, d);
        state[0] = 1.0;
        state[1] = self.time;
        state[2] = count as f64;
        for (i, word) in state[HEADER..].iter_mut().enumerate() {
            let mut bits = 0u64;
            for k in 0..BYTES_PER_WORD {
                let j = i * BYTES_PER_WORD + k;
                if j < count {
                    bits |= u64::from(self.bytes[j]) << (8 * k);
                }
            }
            *word = bits as f64;
        }
        self.shadow.copy_from_slice(state);
        Ok(())
    }

    /// mjPLUGIN_ACTUATOR compute: the force at the current inputs, history unchanged.
    pub unsafe fn compute(&mut self, m: *const MjModel, d: *mut MjData) -> Result<(), String> {
        self.sync(m, d)?;
        self.set_inputs(m, d)?;
        let force = self.instance.get_real(self.config.force.vr)?;
        if !force.is_finite() {
            return Err(format!("output '{}' is {force}", self.config.force.name));
        }
        mj::set_actuator_force(d, self.id, self.config.force_scale * force);
        Ok(())
    }

    /// advance: one FMU step of MuJoCo's timestep with the inputs of this step, history saved.
    pub unsafe fn advance(&mut self, m: *const MjModel, d: *mut MjData) -> Result<(), String> {
        self.sync(m, d)?;
        self.set_inputs(m, d)?;
        let h = mj::timestep(m);
        self.instance.do_step(self.time, h)?;
        self.time += h;
        self.capture(m, d)
    }
}

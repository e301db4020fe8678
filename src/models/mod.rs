//! One file per FMU: maps the generated variables to physics and holds the effect switches.
//!
//! A model is built from its parameters when initialization ends (only the effects switched on),
//! then evaluated and stepped by the export layer through [`Model`]. Models know nothing of FMI
//! calls, states, pointers or value references: they read and write the typed structs generated
//! from their model description.

#![forbid(unsafe_code)]

use crate::variables::{ArrayIdentifier, Identifier, Interface, Row};
use serde::{de::DeserializeOwned, Serialize};
use std::marker::PhantomData;

pub mod free_bladder;
pub mod knitted_muscle;
pub mod mckibben_joint;
pub mod mckibben_muscle;
pub mod multiferroic_motor;
pub mod pass_through;
pub mod pulley_joint;
mod wall_arrays;

/// Outcome of a model call, in FMI's order of severity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    #[default]
    Ok,
    /// The result is usable but something was clamped or approximated; said in the log.
    Warning,
    /// The step could not be completed; the importer may retry from an earlier state.
    Discard,
    Error,
}

/// What a model call has to say: the worst status and the messages that explain it. A report with
/// nothing to say (fmi2OK, nothing clamped, no message) is a null pointer: the per-step path builds
/// and tests one every step, and it owns no memory.
#[derive(Debug, Default)]
pub struct Report {
    /// The model ran (evaluated or stepped): `clamped` describes the outputs it wrote.
    pub evaluated: bool,
    /// Everything else, allocated with the first thing to say.
    notes: Option<Box<Notes>>,
}

#[derive(Debug, Default)]
struct Notes {
    status: Status,
    clamped: bool,
    messages: Vec<(Status, String)>,
    /// Why an input was clamped, logged once per excursion (the first call that leaves the range).
    clamp_messages: Vec<String>,
}

impl Report {
    /// The worst status so far.
    pub fn status(&self) -> Status {
        self.notes.as_ref().map_or(Status::Ok, |n| n.status)
    }
    /// Makes the status at least `status` (without a message: the caller logs why elsewhere).
    pub fn raise(&mut self, status: Status) {
        if status > Status::Ok {
            let notes = self.notes_mut();
            notes.status = notes.status.max(status);
        }
    }
    pub fn add(&mut self, status: Status, message: impl Into<String>) {
        let notes = self.notes_mut();
        notes.status = notes.status.max(status);
        notes.messages.push((status, message.into()));
    }
    pub fn warn(&mut self, message: impl Into<String>) {
        self.add(Status::Warning, message)
    }
    /// Records an input evaluated at the nearest valid point; `message` is built only on the
    /// first call of an excursion (`first`), so that the log gets one line per excursion.
    pub fn clamp(&mut self, first: bool, message: impl FnOnce() -> String) {
        let notes = self.notes_mut();
        notes.clamped = true;
        if first {
            notes.clamp_messages.push(message());
        }
    }
    /// An input lay outside the model's solvable range and was evaluated at the nearest valid
    /// point. The export layer turns this into a status by the `out_of_range_policy` parameter.
    pub fn clamped(&self) -> bool {
        self.notes.as_ref().is_some_and(|n| n.clamped)
    }
    /// The messages with their statuses, in order.
    pub fn messages(&self) -> &[(Status, String)] {
        self.notes.as_ref().map_or(&[], |n| &n.messages)
    }
    /// Why inputs were clamped, if this call began an excursion.
    pub fn clamp_messages(&self) -> &[String] {
        self.notes.as_ref().map_or(&[], |n| &n.clamp_messages)
    }
    /// Takes [`Report::clamp_messages`] out of the report.
    pub fn take_clamp_messages(&mut self) -> Vec<String> {
        self.notes
            .as_mut()
            .map(|n| std::mem::take(&mut n.clamp_messages))
            .unwrap_or_default()
    }
    /// Nothing to say: fmi2OK, nothing clamped, no message.
    pub fn is_quiet(&self) -> bool {
        self.notes.is_none()
    }
    fn notes_mut(&mut self) -> &mut Notes {
        self.notes.get_or_insert_with(Default::default)
    }
}

/// Why a model cannot be built from its parameters: the export layer logs it and refuses
/// initialization (or the parameter change).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal(pub String);

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl From<String> for Refusal {
    fn from(reason: String) -> Self {
        Self(reason)
    }
}

impl From<&str> for Refusal {
    fn from(reason: &str) -> Self {
        Self(reason.to_string())
    }
}

/// Exact partial derivatives of a model's unknowns (outputs, state derivatives) with respect to
/// its knowns (inputs, continuous states) at one point, written against the identifiers generated
/// from its model description (`crate::variables::<model>::{Known, Unknown}`, and one row type
/// per unknown, `<Unknown>By`, whose fields are the knowns it declares): what
/// `fmi2GetDirectionalDerivative` combines with the importer's seed. An unknown without a row is
/// not provided; a known its `<ModelStructure>` entry does not declare has partial 0.
pub struct Partials<V: Interface> {
    /// One row per unknown, one column per known (`Identifier::index`), row after row.
    values: Vec<f64>,
    /// Which rows the model wrote.
    written: Vec<bool>,
    /// Which rows the call reads ([`Partials::wants`]).
    wanted: Vec<bool>,
    marker: PhantomData<fn() -> V>,
}

impl<V: Interface> Partials<V> {
    const COLUMNS: usize = <V::Known as Identifier>::ALL.len();
    const ROWS: usize = <V::Unknown as Identifier>::ALL.len();

    /// No rows yet, every row wanted.
    pub fn new() -> Self {
        let mut partials = Self::default();
        partials.ask_for(V::Unknown::ALL.iter().copied());
        partials
    }

    /// Forgets every row and asks for the rows of `unknowns` (the storage is kept: a Jacobian
    /// taken again allocates nothing).
    pub fn ask_for(&mut self, unknowns: impl Iterator<Item = V::Unknown>) {
        self.values.clear();
        self.values.resize(Self::ROWS * Self::COLUMNS, 0.0);
        self.written.clear();
        self.written.resize(Self::ROWS, false);
        self.wanted.clear();
        self.wanted.resize(Self::ROWS, false);
        for unknown in unknowns {
            self.wanted[unknown.index()] = true;
        }
    }

    /// Whether the call reads the row of `unknown`: a model may leave out a costly row (the
    /// stiffness's second derivatives) that is not wanted. Writing it anyway is never wrong.
    pub fn wants(&self, unknown: V::Unknown) -> bool {
        self.wanted.get(unknown.index()).copied().unwrap_or(true)
    }

    /// Writes a row: `p.row(ForceBy { pressure: dp, length: dl })`, the partials of its unknown
    /// by the knowns its `<ModelStructure>` entry declares (zero by every other known).
    pub fn row<R: Row<Variables = V>>(&mut self, row: R) -> &mut Self {
        if self.written.is_empty() {
            self.ask_for(std::iter::empty());
        }
        let unknown = R::UNKNOWN.index();
        let values = &mut self.values[unknown * Self::COLUMNS..(unknown + 1) * Self::COLUMNS];
        values.fill(0.0);
        row.write(|known, d| values[known.index()] = d);
        self.written[unknown] = true;
        self
    }

    /// The row of `unknown`, by known ([`Identifier::index`]), if provided.
    pub fn get(&self, unknown: V::Unknown) -> Option<&[f64]> {
        let start = unknown.index() * Self::COLUMNS;
        match self.written.get(unknown.index()) {
            Some(true) => Some(&self.values[start..start + Self::COLUMNS]),
            _ => None,
        }
    }

    /// `d unknown / d known`, if the row of `unknown` is provided.
    pub fn partial(&self, unknown: V::Unknown, known: V::Known) -> Option<f64> {
        self.get(unknown).map(|row| row[known.index()])
    }

    /// The unknowns that have a row.
    pub fn unknowns(&self) -> impl Iterator<Item = V::Unknown> + '_ {
        V::Unknown::ALL
            .iter()
            .copied()
            .filter(|u| self.get(*u).is_some())
    }
}

/// Empty: no storage until the first row.
impl<V: Interface> Default for Partials<V> {
    fn default() -> Self {
        Self {
            values: Vec::new(),
            written: Vec::new(),
            wanted: Vec::new(),
            marker: PhantomData,
        }
    }
}

// By hand: a derive would ask the marker type for them.
impl<V: Interface> Clone for Partials<V> {
    fn clone(&self) -> Self {
        Self {
            values: self.values.clone(),
            written: self.written.clone(),
            wanted: self.wanted.clone(),
            marker: PhantomData,
        }
    }
}

/// Equal when the same rows hold the same values (what was asked for aside).
impl<V: Interface> PartialEq for Partials<V> {
    fn eq(&self, other: &Self) -> bool {
        V::Unknown::ALL.iter().all(|&u| self.get(u) == other.get(u))
    }
}

impl<V: Interface> std::fmt::Debug for Partials<V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_map()
            .entries(self.unknowns().map(|u| (u, self.get(u))))
            .finish()
    }
}

/// What a model's partials depend on besides its inputs ([`Model::partials_key`]): up to four
/// numbers of its history, compared bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HistoryKey([u64; 4]);

impl HistoryKey {
    /// The partials depend on the inputs alone.
    pub const NONE: Self = Self([0; 4]);

    /// The partials depend on `history` (at most four numbers) besides the inputs.
    pub fn of<const N: usize>(history: [f64; N]) -> Self {
        const { assert!(N <= 4, "a HistoryKey holds at most four numbers") };
        let mut bits = [0; 4];
        for (slot, x) in bits.iter_mut().zip(history) {
            *slot = x.to_bits();
        }
        Self(bits)
    }
}

/// The typed variable groups of model `M`, generated from its model description.
pub type Parameters<M> = <<M as Model>::Variables as Interface>::Parameters;
pub type Inputs<M> = <<M as Model>::Variables as Interface>::Inputs;
pub type Outputs<M> = <<M as Model>::Variables as Interface>::Outputs;
pub type CalculatedParameters<M> = <<M as Model>::Variables as Interface>::CalculatedParameters;
/// The continuous states of model `M` (and their derivatives), generated from the variables that
/// carry a `derivative` attribute; an empty struct for models without states.
pub type States<M> = <<M as Model>::Variables as Interface>::States;
/// The FMI 3.0 array outputs of model `M`: an empty enum for models without arrays.
pub type ArrayOutput<M> = <<M as Model>::Variables as Interface>::ArrayOutput;

/// What an event update (`fmi2NewDiscreteStates`) did, for `fmi2EventInfo`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EventUpdate {
    /// The continuous states jumped: the importer must read them again
    /// (`valuesOfContinuousStatesChanged`).
    pub states_changed: bool,
    /// Another event iteration is needed at the same time (`newDiscreteStatesNeeded`).
    pub iterate: bool,
    /// The model cannot go on (`terminateSimulation`); say why in the report.
    pub terminate: bool,
}

/// A co-simulation model. It sees its variables only as the typed structs generated from its
/// model description (`crate::variables::<model>`); the export layer owns their values. The model
/// owns its physics and its history (friction state, onion state, rotor state), which is part of
/// the FMU state.
///
/// Model Exchange extends it through defaults that co-simulation-only models never write, so an
/// algebraic model compiles unchanged. A model with continuous states (declared in its model
/// description: a `local` Real `der(x)` with `derivative="x"`, and x listed in `<Derivatives>`)
/// implements, besides `new`, `evaluate` and `step`:
/// - [`Model::MODEL_EXCHANGE`] `= true`;
/// - [`Model::states`] and [`Model::set_states`]: the model owns its states (they are its
///   co-simulation history too, so FMU states save them with the model);
/// - [`Model::set_time`]: the independent variable; [`Model::evaluate`] then writes the outputs
///   at the current states, time and inputs;
/// - [`Model::derivatives`]: `dx/dt` at the current states, time and inputs (no allocation: it
///   is the integrator's hot path);
/// - optionally [`Model::next_time_event`], [`Model::event_indicators`] (as many as
///   `numberOfEventIndicators`), [`Model::update_discrete_states`] (event mode: may move the
///   states, say so in [`EventUpdate`]) and [`Model::completed_integrator_step`];
/// - optionally [`Model::partials`] with rows for the outputs and the derivative variables
///   (`Unknown::DerX`) and columns for the inputs and the states (`Known::X`): the export layer
///   then serves `fmi2GetDirectionalDerivative` for Model Exchange's Jacobian.
///
/// The export layer calls, for one right-hand side: `set_time`, `set_states` (only when the
/// importer set them), then `derivatives`, `event_indicators` or `evaluate` in any order.
pub trait Model: Clone + Send + Serialize + DeserializeOwned + 'static {
    /// The generated interface, `crate::variables::<model>::Variables`.
    type Variables: Interface;
    /// HTML fragment for the FMU's `documentation/index.html`: the equations it implements.
    const DOCUMENTATION: &'static str;

    /// Builds the model from its parameters, with only the effects they switch on; `start` are the
    /// inputs when initialization ends (the history starts there). An unusable parameter set is a
    /// [`Refusal`] that says which and why.
    fn new(parameters: &Parameters<Self>, start: &Inputs<Self>) -> Result<Self, Refusal>;

    /// The calculated parameters of the built model (none by default).
    fn calculated_parameters(&self) -> CalculatedParameters<Self> {
        Default::default()
    }

    /// Writes the outputs for `inputs` and the current history, without advancing the history.
    /// Outputs it leaves alone keep their previous values.
    fn evaluate(&mut self, inputs: &Inputs<Self>, outputs: &mut Outputs<Self>, report: &mut Report);

    /// Advances from `time` to `time + step` with `inputs` held, commits the history and writes
    /// the outputs at the end of the step.
    fn step(
        &mut self,
        inputs: &Inputs<Self>,
        outputs: &mut Outputs<Self>,
        time: f64,
        step: f64,
        report: &mut Report,
    );

    /// Whether the model serves FMI Model Exchange without continuous states: its outputs are
    /// algebraic in the inputs and its history (friction) is a discrete state, committed by
    /// [`Model::update_discrete_states`] at each completed integrator step and event.
    const ALGEBRAIC_MODEL_EXCHANGE: bool = false;

    /// Whether the model serves FMI Model Exchange: algebraic models, and models with continuous
    /// states that implement the methods below.
    const MODEL_EXCHANGE: bool = Self::ALGEBRAIC_MODEL_EXCHANGE;

    /// Model Exchange, event mode (`fmi2NewDiscreteStates`): commits the history at `inputs` and
    /// time `time`, may move the continuous states (reinit) and writes the outputs there. The
    /// default is a step of zero length, right for a quasi-static model.
    fn update_discrete_states(
        &mut self,
        inputs: &Inputs<Self>,
        outputs: &mut Outputs<Self>,
        time: f64,
        report: &mut Report,
    ) -> EventUpdate {
        self.step(inputs, outputs, time, 0.0, report);
        EventUpdate::default()
    }

    /// Model Exchange: the integrator accepted its step at `time` (`fmi2CompletedIntegratorStep`).
    /// Returns whether the model needs an event there (`enterEventMode`). The default commits the
    /// history as [`Model::update_discrete_states`] does and asks for no event; a model whose
    /// discrete states may change only at events overrides it.
    fn completed_integrator_step(
        &mut self,
        inputs: &Inputs<Self>,
        outputs: &mut Outputs<Self>,
        time: f64,
        report: &mut Report,
    ) -> bool {
        self.update_discrete_states(inputs, outputs, time, report);
        false
    }

    /// The continuous states now (none by default).
    fn states(&self) -> States<Self> {
        Default::default()
    }

    /// Takes the states the integrator proposes (`fmi2SetContinuousStates`; finite, checked by
    /// the export layer). A state the model cannot take (outside its domain) is an `Err` saying
    /// why; the model then keeps its previous states.
    fn set_states(&mut self, _states: &States<Self>) -> Result<(), String> {
        Ok(())
    }

    /// Model Exchange: the independent variable is now `time` (`fmi2SetTime`, and the start
    /// time when the model is built for Model Exchange).
    fn set_time(&mut self, _time: f64) {}

    /// The state derivatives `dx/dt` at the current states and time and at `inputs`. An `Err`
    /// says why there are none (the export layer logs it and returns fmi2Error); a finite result
    /// is checked by the export layer.
    fn derivatives(&mut self, _inputs: &Inputs<Self>) -> Result<States<Self>, String> {
        Ok(Default::default())
    }

    /// The event indicators at the current states and time and at `inputs`, into `out`
    /// (`numberOfEventIndicators` values): an event happens where one changes sign.
    fn event_indicators(&mut self, _inputs: &Inputs<Self>, _out: &mut [f64]) -> Result<(), String> {
        Ok(())
    }

    /// The next time event after the event at `time` (`nextEventTime`), if any.
    fn next_time_event(&self, _time: f64) -> Option<f64> {
        None
    }

    /// The FMI 3.0 array output `array` (an `<Array>` of the model description's
    /// VendorAnnotations) at `inputs` and the current history, into `out` (its declared size).
    /// Computed only when an importer reads it, so an array nobody reads costs nothing. `Err`
    /// says why there is no value; by default the model computes none.
    fn array(
        &self,
        _inputs: &Inputs<Self>,
        array: ArrayOutput<Self>,
        _out: &mut [f64],
    ) -> Result<(), String> {
        Err(format!("this model does not compute {}", array.name()))
    }

    /// Exact partial derivatives of the outputs (and, with states, of the derivative variables
    /// `der(x)`) with respect to the inputs (and the states `x`) at `inputs` and the current
    /// history, on the branch [`Model::evaluate`] takes (analytic or forward-mode, never finite
    /// differences), written as rows of `partials` through the generated row types, whose fields
    /// are the declared dependencies (`partials.row(YBy { u: 2.0 })`). `partials` comes empty; a
    /// row the call does not read (`!partials.wants(unknown)`) may be left out when it costs more
    /// than the others (the stiffness's second derivatives). `Err` says why there are none: by default
    /// this model does not provide them, and its model description says
    /// `providesDirectionalDerivative="false"`.
    fn partials(
        &mut self,
        _inputs: &Inputs<Self>,
        _partials: &mut Partials<Self::Variables>,
    ) -> Result<(), String> {
        Err("this model does not provide partial derivatives".into())
    }

    /// What [`Model::partials`] depends on besides the inputs, so that the export layer may reuse
    /// them for the further seeds of a Jacobian at the same point: [`HistoryKey::NONE`] for
    /// partials of the inputs alone, [`HistoryKey::of`] the history they read (friction state)
    /// otherwise. `None`, the default, reuses nothing: the partials are taken afresh at every
    /// call, right whatever they depend on (time, states, schedules).
    fn partials_key(&self) -> Option<HistoryKey> {
        None
    }

    /// Takes over the history of `saved`, a model deserialized from an importer's bytes, after
    /// checking it against the model's invariants. `self` was rebuilt by [`Model::new`] from the
    /// parameters that came with `saved`, so nothing derived from parameters (limits, geometry,
    /// caches) is taken from the bytes. A history no legal call sequence produces is an `Err`
    /// saying which. The default, for models without history, takes nothing.
    fn adopt_history(&mut self, _saved: &Self) -> Result<(), String> {
        Ok(())
    }
}

/// Every row of [`Model::partials`] at `inputs`, in a fresh [`Partials`]: for the models' tests.
#[cfg(test)]
pub(crate) fn all_partials<M: Model>(
    model: &mut M,
    inputs: &Inputs<M>,
) -> Result<Partials<M::Variables>, String> {
    let mut partials = Partials::new();
    model.partials(inputs, &mut partials)?;
    Ok(partials)
}

//! `fmi2GetDirectionalDerivative`: the importer's seed `dv_known` over inputs (and continuous
//! states), times the model's exact partials ([`Model::partials`]), gives `dv_unknown` over
//! outputs (and state derivatives): Model Exchange's Jacobian. No finite differences: a model
//! that has no partials says so and the call is refused.
//!
//! Value references become the model's generated identifiers ([`Identifier`]) here, and the
//! partials are kept ([`PartialsCache`]) for the further seeds of a Jacobian at the same point.

use super::Bindings;
use crate::models::{HistoryKey, Inputs, Model, Partials};
use crate::variables::{ContinuousStates, Identical, Identifier, Interface, VarType};

/// The last partials of one instance and the point they were taken at: a Jacobian is one call
/// per seed, and a muscle's partials cost a bladder pass (a second-order one for the stiffness).
pub(super) struct PartialsCache<V: Interface> {
    /// The inputs and the model's [`HistoryKey`] the partials hold at; `None` when they are not
    /// reusable (none yet, a model that keys nothing, a new model).
    at: Option<(V::Inputs, HistoryKey)>,
    partials: Partials<V>,
}

impl<V: Interface> Default for PartialsCache<V> {
    fn default() -> Self {
        Self {
            at: None,
            partials: Partials::default(),
        }
    }
}

impl<V: Interface> PartialsCache<V> {
    /// Forgets the partials: the model they came from was replaced.
    pub(super) fn forget(&mut self) {
        self.at = None;
    }

    /// The partials of `model` at `inputs` with at least the rows of `unknowns` (those it
    /// provides): the kept ones if they were taken at the same inputs and history and hold
    /// those rows, else fresh ones.
    pub(super) fn partials_of<M: Model<Variables = V>>(
        &mut self,
        model: &mut M,
        inputs: &V::Inputs,
        unknowns: &[u32],
    ) -> Result<&Partials<V>, String> {
        let key = model.partials_key();
        let reusable = match (&self.at, key) {
            (Some((at, kept)), Some(key)) => {
                *kept == key
                    && at.identical(inputs)
                    && unknowns.iter().all(|&vr| {
                        V::Unknown::from_value_reference(vr)
                            .is_some_and(|u| self.partials.get(u).is_some())
                    })
            }
            _ => false,
        };
        if !reusable {
            self.at = None;
            self.partials.ask_for(
                unknowns
                    .iter()
                    .filter_map(|&vr| V::Unknown::from_value_reference(vr)),
            );
            model.partials(inputs, &mut self.partials)?;
            self.at = key.map(|key| (inputs.clone(), key));
        }
        Ok(&self.partials)
    }
}

/// `dv_unknown[i] = sum_j d(unknown_i)/d(known_j) dv_known[j]` for model `M` at the current inputs.
pub(super) fn directional_derivative<M: Model>(
    model: Option<&mut M>,
    cache: &mut PartialsCache<M::Variables>,
    inputs: &Inputs<M>,
    unknown: &[u32],
    known: &[u32],
    dv_known: &[f64],
    dv_unknown: &mut [f64],
) -> Result<(), String>
where
    M::Variables: Bindings,
{
    type V<M> = <M as Model>::Variables;
    type Known<M> = <V<M> as Interface>::Known;
    type Unknown<M> = <V<M> as Interface>::Unknown;
    let info = V::<M>::INFO;
    let has_states = <V<M> as Interface>::States::COUNT > 0;
    let name = |vr: u32| info.variable(VarType::Real, vr).map_or("?", |v| v.name);
    // Knowns: inputs and continuous states; unknowns: outputs and state derivatives.
    let refusal = |vr: u32, role: &str| match info.variable(VarType::Real, vr) {
        None => format!("{vr} is not the value reference of a Real variable"),
        Some(var) => format!(
            "{} (value reference {vr}) is not {role} of {}",
            var.name, info.name
        ),
    };
    if let Some(&vr) = known
        .iter()
        .find(|&&vr| Known::<M>::from_value_reference(vr).is_none())
    {
        let role = if has_states {
            "an input or a continuous state"
        } else {
            "an input"
        };
        return Err(refusal(vr, role));
    }
    if let Some(&vr) = unknown
        .iter()
        .find(|&&vr| Unknown::<M>::from_value_reference(vr).is_none())
    {
        let role = if has_states {
            "an output or a state derivative"
        } else {
            "an output"
        };
        return Err(refusal(vr, role));
    }
    if let Some(bad) = dv_known.iter().find(|v| !v.is_finite()) {
        return Err(format!("dvKnown must be finite, got {bad}"));
    }
    let model = model.ok_or("no model yet: call it in initialization mode or later")?;
    let partials = cache.partials_of(model, inputs, unknown)?;
    for (slot, &vr) in dv_unknown.iter_mut().zip(unknown) {
        let row = Unknown::<M>::from_value_reference(vr)
            .and_then(|output| partials.get(output))
            .ok_or_else(|| format!("the partial derivatives of {} are not provided", name(vr)))?;
        let value: f64 = known
            .iter()
            .zip(dv_known)
            .filter_map(|(&vr, seed)| {
                Known::<M>::from_value_reference(vr).map(|input| row[input.index()] * seed)
            })
            .sum();
        if !value.is_finite() {
            return Err(format!("the derivative of {} overflows", name(vr)));
        }
        *slot = value;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::mckibben_muscle::McKibbenMuscle;
    use crate::models::{all_partials, Report};
    use crate::variables::mckibben_muscle::{real, Inputs, Outputs, Parameters, Unknown};

    type Cache = PartialsCache<<McKibbenMuscle as Model>::Variables>;

    const FORCE: u32 = real::FORCE as u32;
    const STIFFNESS: u32 = real::STIFFNESS as u32;

    /// The kept partials are those of the current point: a further seed at the same inputs and
    /// history reuses them, new inputs or a committed friction history take them afresh.
    #[test]
    fn kept_partials_follow_the_inputs_and_the_history() {
        let p = Parameters {
            preset: 2,
            friction: true,
            ..Default::default()
        };
        let at = |length: f64| Inputs {
            pressure: 3e5,
            length,
            ..Default::default()
        };
        let start = at(0.7
            * McKibbenMuscle::new(&p, &at(0.0))
                .unwrap()
                .calculated_parameters()
                .max_length);
        let (a, b) = (at(start.length + 3e-5), at(start.length + 1e-4));
        let mut m = McKibbenMuscle::new(&p, &start).unwrap();
        let mut cache = Cache::default();
        let mut partials = |m: &mut McKibbenMuscle, x: &Inputs| {
            cache
                .partials_of(m, x, &[FORCE, STIFFNESS])
                .unwrap()
                .clone()
        };
        let first = partials(&mut m, &a);
        assert_eq!(first, all_partials(&mut m, &a).unwrap());
        assert_eq!(partials(&mut m, &a), first);
        let other = partials(&mut m, &b);
        assert_ne!(other, first);
        assert_eq!(other, all_partials(&mut m, &b).unwrap());
        assert_eq!(partials(&mut m, &a), first);
        // A step to `b` moves the friction history: the partials at `a` change with it.
        m.step(
            &b,
            &mut Outputs::default(),
            0.0,
            1e-3,
            &mut Report::default(),
        );
        let after = partials(&mut m, &a);
        assert_eq!(after, all_partials(&mut m, &a).unwrap());
        assert_ne!(
            after.get(Unknown::FrictionForce),
            first.get(Unknown::FrictionForce)
        );
    }

    /// A call that asks for the stiffness is not served from partials taken without it (its row
    /// is a second-order pass, left out when not asked for); once taken, a call for fewer rows
    /// reuses them.
    #[test]
    fn kept_partials_serve_only_the_rows_they_hold() {
        let p = Parameters {
            preset: 4,
            bladder_model: 2,
            bladder_layers: 4,
            friction: true,
            connector_stiffness: 5e4,
            ..Default::default()
        };
        let x = Inputs {
            pressure: 3e5,
            length: 0.12,
            ..Default::default()
        };
        let mut m = McKibbenMuscle::new(&p, &x).unwrap();
        let mut cache = Cache::default();
        let first = cache.partials_of(&mut m, &x, &[FORCE]).unwrap().clone();
        assert!(first.get(Unknown::Stiffness).is_none());
        let with = cache
            .partials_of(&mut m, &x, &[FORCE, STIFFNESS])
            .unwrap()
            .clone();
        assert_eq!(with, all_partials(&mut m, &x).unwrap());
        assert_eq!(with.get(Unknown::Force), first.get(Unknown::Force));
        // Served from the cache, stiffness included.
        assert_eq!(cache.partials_of(&mut m, &x, &[FORCE]).unwrap(), &with);
        // Forgotten with the model: taken afresh, for the rows asked for.
        cache.forget();
        assert_eq!(cache.partials_of(&mut m, &x, &[FORCE]).unwrap(), &first);
    }

    /// A model rebuilt from other parameters (a tunable parameter set between steps, an FMU
    /// state restored) never gets the partials kept for the one it replaced, though the inputs
    /// and its history are the same.
    #[test]
    fn kept_partials_go_with_the_model() -> Result<(), String> {
        use crate::export::runtime::{Factory, ModelFactory, Runtime};
        let (pressure, length, turns) = (real::PRESSURE, real::LENGTH, real::TURNS);
        let derivative = |runtime: &mut dyn Runtime| -> Result<f64, String> {
            let mut dv = [0.0];
            runtime.directional_derivative(&[FORCE], &[pressure as u32], &[1.0], &mut dv)?;
            Ok(dv[0])
        };
        let runtime_with = |n: f64| -> Result<Box<dyn Runtime>, String> {
            let mut runtime = ModelFactory::<McKibbenMuscle>::NEW.create();
            runtime.set_real(turns, n);
            runtime.set_real(pressure, 3e5);
            runtime.set_real(length, 0.1);
            runtime.changed(true);
            runtime.build()?;
            Ok(runtime)
        };
        let mut runtime = runtime_with(3.74)?;
        let before = derivative(&mut *runtime)?;
        runtime.set_real(turns, 4.5);
        runtime.changed(true);
        runtime.build()?;
        let after = derivative(&mut *runtime)?;
        assert_ne!(after, before);
        assert_eq!(after, derivative(&mut *runtime_with(4.5)?)?);
        Ok(())
    }
}

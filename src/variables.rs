//! Variable metadata and typed variable groups generated from `modelDescription/*.xml` by
//! build.rs, and the types they use. Nothing here names the models or the export layer: the
//! models read these types, the export layer (`crate::fmi2`) binds them to value references.

/// FMI base type of a variable; its value reference indexes the array of that type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
    Independent,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Initial {
    Exact,
    Approx,
    Calculated,
    /// Inputs and the independent variable carry no `initial` attribute.
    None,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    None,
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(&'static str),
}

/// One `ScalarVariable` of a model description.
#[derive(Debug)]
pub struct Variable {
    pub name: &'static str,
    pub kind: VarType,
    pub vr: u32,
    pub causality: Causality,
    pub variability: Variability,
    pub initial: Initial,
    pub start: Start,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub unit: &'static str,
    pub description: &'static str,
}

/// Everything the export layer and the packager need to know about one model.
#[derive(Debug)]
pub struct ModelInfo {
    pub name: &'static str,
    pub guid: &'static str,
    pub description: &'static str,
    /// The model description as shipped in the FMU (guid filled in).
    pub model_description_xml: &'static str,
    pub variables: &'static [Variable],
    /// Number of Real, Integer, Boolean and String variables.
    pub counts: [usize; 4],
    pub log_categories: &'static [&'static str],
}

impl ModelInfo {
    /// The variable of a type and value reference, if there is one.
    pub fn variable(&self, kind: VarType, vr: u32) -> Option<&'static Variable> {
        self.variables.iter().find(|v| v.kind == kind && v.vr == vr)
    }

    pub fn by_name(&self, name: &str) -> Option<&'static Variable> {
        self.variables.iter().find(|v| v.name == name)
    }
}

use serde::{de::DeserializeOwned, Serialize};

/// One model's typed variable groups, generated per model description as
/// `crate::variables::<model>::Variables`. Field names are the variable names in snake case, so a
/// renamed variable is a compile error in the model that uses it.
///
/// Model Exchange (continuous states, derivatives, event indicators) would add its groups here as
/// further associated types, generated from `<ModelStructure><Derivatives>`.
pub trait Interface: 'static {
    /// Parameters (fixed or tunable); `Default` gives the start values.
    type Parameters: Clone
        + std::fmt::Debug
        + Default
        + PartialEq
        + Send
        + Serialize
        + DeserializeOwned;
    /// Inputs; `Default` gives the start values.
    type Inputs: Clone + std::fmt::Debug + Default + PartialEq + Send + Serialize + DeserializeOwned;
    /// Outputs; `Default` gives zeros (or declared start values).
    type Outputs: Clone
        + std::fmt::Debug
        + Default
        + PartialEq
        + Send
        + Serialize
        + DeserializeOwned;
    /// Calculated parameters, written once when the model is built.
    type CalculatedParameters: Clone
        + std::fmt::Debug
        + Default
        + PartialEq
        + Send
        + Serialize
        + DeserializeOwned;
    /// Metadata of every variable.
    const INFO: &'static ModelInfo;
}

include!(concat!(env!("OUT_DIR"), "/model_tables.rs"));

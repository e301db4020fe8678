//! The one reader of an FMI 2.0 model description: serde structs over quick-xml. It reads a source
//! (`modelDescription/<Model>.xml`) and a shipped description alike; the code generator's checks
//! (`variable_checks.rs`) and the FMI 2.0 rules (`rules.rs`) are checks over this typed data, and
//! the FMI 3.0 description (`fmi3_description.rs`, `fmi3_arrays.rs`) and terminals
//! (`terminals.rs`) are written from it, with what the source's own `<Tool>` declares for FMI 3.0
//! only (its `<Terminals>` and `<Arrays>`).
//!
//! Attribute values the rules judge are kept as text, so that a bad one is refused with a reason
//! rather than a parse error. A list element (`Unit`, `ScalarVariable`, `Unknown`, ...) must be
//! written as one run of siblings, as the FMI 2.0 schema's sequences require.

use serde::Deserialize;

#[derive(Deserialize)]
pub struct Description {
    #[serde(rename = "@fmiVersion")]
    pub fmi_version: String,
    #[serde(rename = "@modelName")]
    pub model_name: String,
    #[serde(rename = "@guid")]
    pub guid: String,
    #[serde(rename = "@description", default)]
    pub description: String,
    #[serde(rename = "@variableNamingConvention")]
    pub variable_naming_convention: Option<String>,
    #[serde(rename = "@numberOfEventIndicators")]
    pub number_of_event_indicators: Option<String>,
    #[serde(rename = "ModelExchange")]
    pub model_exchange: Option<Capabilities>,
    #[serde(rename = "CoSimulation")]
    pub co_simulation: Option<Capabilities>,
    #[serde(rename = "UnitDefinitions", default)]
    pub unit_definitions: UnitDefinitions,
    #[serde(rename = "TypeDefinitions", default)]
    pub type_definitions: TypeDefinitions,
    #[serde(rename = "LogCategories")]
    pub log_categories: Option<LogCategories>,
    #[serde(rename = "DefaultExperiment")]
    pub default_experiment: Option<DefaultExperiment>,
    #[serde(rename = "VendorAnnotations")]
    pub vendor_annotations: Option<VendorAnnotations>,
    #[serde(rename = "ModelVariables")]
    pub model_variables: ModelVariables,
    #[serde(rename = "ModelStructure", default)]
    pub model_structure: ModelStructure,
}

/// Reads a model description; the error says where the XML does not fit.
pub fn parse(text: &str) -> Result<Description, String> {
    quick_xml::de::from_str(text).map_err(|e| format!("cannot parse: {e}"))
}

/// `<ModelExchange>` or `<CoSimulation>`: the boolean capability flags, as written.
#[derive(Deserialize)]
pub struct Capabilities {
    #[serde(rename = "@needsExecutionTool")]
    needs_execution_tool: Option<String>,
    #[serde(rename = "@completedIntegratorStepNotNeeded")]
    completed_integrator_step_not_needed: Option<String>,
    #[serde(rename = "@canBeInstantiatedOnlyOncePerProcess")]
    can_be_instantiated_only_once_per_process: Option<String>,
    #[serde(rename = "@canNotUseMemoryManagementFunctions")]
    can_not_use_memory_management_functions: Option<String>,
    #[serde(rename = "@canGetAndSetFMUstate")]
    can_get_and_set_fmu_state: Option<String>,
    #[serde(rename = "@canSerializeFMUstate")]
    can_serialize_fmu_state: Option<String>,
    #[serde(rename = "@providesDirectionalDerivative")]
    provides_directional_derivative: Option<String>,
    #[serde(rename = "@canHandleVariableCommunicationStepSize")]
    can_handle_variable_communication_step_size: Option<String>,
    #[serde(rename = "@canInterpolateInputs")]
    can_interpolate_inputs: Option<String>,
    #[serde(rename = "@canRunAsynchronuously")]
    can_run_asynchronuously: Option<String>,
}

impl Capabilities {
    /// (attribute, value) of every boolean flag present.
    pub fn flags(&self) -> Vec<(&'static str, &str)> {
        [
            ("needsExecutionTool", &self.needs_execution_tool),
            (
                "completedIntegratorStepNotNeeded",
                &self.completed_integrator_step_not_needed,
            ),
            (
                "canBeInstantiatedOnlyOncePerProcess",
                &self.can_be_instantiated_only_once_per_process,
            ),
            (
                "canNotUseMemoryManagementFunctions",
                &self.can_not_use_memory_management_functions,
            ),
            ("canGetAndSetFMUstate", &self.can_get_and_set_fmu_state),
            ("canSerializeFMUstate", &self.can_serialize_fmu_state),
            (
                "providesDirectionalDerivative",
                &self.provides_directional_derivative,
            ),
            (
                "canHandleVariableCommunicationStepSize",
                &self.can_handle_variable_communication_step_size,
            ),
            ("canInterpolateInputs", &self.can_interpolate_inputs),
            ("canRunAsynchronuously", &self.can_run_asynchronuously),
        ]
        .into_iter()
        .filter_map(|(key, value)| value.as_deref().map(|v| (key, v)))
        .collect()
    }
}

#[derive(Deserialize, Default)]
pub struct UnitDefinitions {
    #[serde(rename = "Unit", default)]
    pub units: Vec<Unit>,
}

#[derive(Deserialize)]
pub struct Unit {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "BaseUnit")]
    pub base_unit: Option<BaseUnit>,
}

/// The SI exponents (integers) and the factor and offset of a unit.
#[derive(Deserialize)]
pub struct BaseUnit {
    #[serde(rename = "@kg")]
    kg: Option<String>,
    #[serde(rename = "@m")]
    m: Option<String>,
    #[serde(rename = "@s")]
    s: Option<String>,
    #[serde(rename = "@A")]
    ampere: Option<String>,
    #[serde(rename = "@K")]
    kelvin: Option<String>,
    #[serde(rename = "@mol")]
    mol: Option<String>,
    #[serde(rename = "@cd")]
    cd: Option<String>,
    #[serde(rename = "@rad")]
    rad: Option<String>,
    #[serde(rename = "@factor")]
    pub factor: Option<String>,
    #[serde(rename = "@offset")]
    pub offset: Option<String>,
}

impl BaseUnit {
    /// (exponent attribute, value) of every exponent present.
    pub fn exponents(&self) -> Vec<(&'static str, &str)> {
        [
            ("kg", &self.kg),
            ("m", &self.m),
            ("s", &self.s),
            ("A", &self.ampere),
            ("K", &self.kelvin),
            ("mol", &self.mol),
            ("cd", &self.cd),
            ("rad", &self.rad),
        ]
        .into_iter()
        .filter_map(|(key, value)| value.as_deref().map(|v| (key, v)))
        .collect()
    }
}

#[derive(Deserialize, Default)]
pub struct TypeDefinitions {
    #[serde(rename = "SimpleType", default)]
    pub types: Vec<SimpleType>,
}

/// The generator supports Enumeration types only (a variable gives its unit directly); the rules
/// read any.
#[derive(Deserialize)]
pub struct SimpleType {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@description")]
    pub description: Option<String>,
    #[serde(rename = "Real")]
    pub real: Option<TypeAttributes>,
    #[serde(rename = "Enumeration")]
    pub enumeration: Option<EnumerationType>,
}

#[derive(Deserialize)]
pub struct EnumerationType {
    #[serde(rename = "Item", default)]
    pub items: Vec<Item>,
}

#[derive(Deserialize)]
pub struct Item {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@value")]
    pub value: i32,
    #[serde(rename = "@description")]
    pub description: Option<String>,
}

#[derive(Deserialize)]
pub struct LogCategories {
    #[serde(rename = "Category", default)]
    pub categories: Vec<Category>,
}

#[derive(Deserialize)]
pub struct Category {
    #[serde(rename = "@name")]
    pub name: String,
}

#[derive(Deserialize)]
pub struct DefaultExperiment {
    #[serde(rename = "@startTime")]
    pub start_time: Option<String>,
    #[serde(rename = "@stopTime")]
    pub stop_time: Option<String>,
    #[serde(rename = "@tolerance")]
    pub tolerance: Option<String>,
    #[serde(rename = "@stepSize")]
    pub step_size: Option<String>,
}

#[derive(Deserialize)]
pub struct VendorAnnotations {
    #[serde(rename = "Tool", default)]
    pub tools: Vec<Tool>,
}

#[derive(Deserialize)]
pub struct Tool {
    #[serde(rename = "@name")]
    pub name: String,
    /// Every child element, in order.
    #[serde(rename = "$value", default)]
    pub elements: Vec<ToolElement>,
}

/// A child of a `<Tool>`: the source's `<Terminals>` (the FMI 3.0 flanges, `terminals.rs`) or
/// `<Arrays>` (the FMI 3.0 array outputs, `fmi3_arrays.rs`), which build.rs moves out of the FMI
/// 2.0 description, or any other element.
#[derive(Deserialize)]
pub enum ToolElement {
    Terminals(Terminals),
    Arrays(Arrays),
    #[serde(other)]
    Other,
}

/// The name of the `<Tool>` whose elements are this project's own.
const TOOL: &str = "actuator-fmus";

impl Description {
    /// The elements of this project's own `<Tool>`s, in order.
    fn own_elements(&self) -> impl Iterator<Item = &ToolElement> {
        self.vendor_annotations
            .iter()
            .flat_map(|a| &a.tools)
            .filter(|t| t.name == TOOL)
            .flat_map(|t| &t.elements)
    }

    /// The mechanical flanges the source declares (`<Terminals>`), in order.
    pub fn flanges(&self) -> impl Iterator<Item = &Flange> {
        self.own_elements()
            .filter_map(|e| match e {
                ToolElement::Terminals(t) => Some(&t.flanges),
                _ => None,
            })
            .flatten()
    }

    /// The FMI 3.0 array outputs the source declares (`<Arrays>`), in order.
    pub fn arrays(&self) -> impl Iterator<Item = &ArrayDeclaration> {
        self.own_elements()
            .filter_map(|e| match e {
                ToolElement::Arrays(a) => Some(&a.arrays),
                _ => None,
            })
            .flatten()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Terminals {
    #[serde(rename = "Flange", default)]
    pub flanges: Vec<Flange>,
}

/// `<Flange name kind position|angle force|torque flow description/>`: a mechanical flange of the
/// FMI 3.0 FMU (`terminals.rs` checks it).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Flange {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@kind")]
    pub kind: String,
    #[serde(rename = "@position")]
    pub position: Option<String>,
    #[serde(rename = "@force")]
    pub force: Option<String>,
    #[serde(rename = "@angle")]
    pub angle: Option<String>,
    #[serde(rename = "@torque")]
    pub torque: Option<String>,
    #[serde(rename = "@flow")]
    pub flow: String,
    #[serde(rename = "@description")]
    pub description: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arrays {
    #[serde(rename = "Array", default)]
    pub arrays: Vec<ArrayDeclaration>,
}

/// `<Array name size unit description dependenciesOf/>`: an FMI 3.0 array output
/// (`fmi3_arrays.rs` checks it).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArrayDeclaration {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@size")]
    pub size: u64,
    #[serde(rename = "@unit")]
    pub unit: Option<String>,
    #[serde(rename = "@description")]
    pub description: Option<String>,
    /// The scalar output whose dependencies the array has.
    #[serde(rename = "@dependenciesOf")]
    pub dependencies_of: String,
}

#[derive(Deserialize)]
pub struct ModelVariables {
    #[serde(rename = "ScalarVariable", default)]
    pub variables: Vec<ScalarVariable>,
}

#[derive(Deserialize)]
pub struct ScalarVariable {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@valueReference")]
    pub value_reference: u32,
    #[serde(rename = "@description", default)]
    pub description: String,
    #[serde(rename = "@causality", default = "default_causality")]
    pub causality: String,
    #[serde(rename = "@variability", default = "default_variability")]
    pub variability: String,
    #[serde(rename = "@initial")]
    pub initial: Option<String>,
    #[serde(rename = "@canHandleMultipleSetPerTimeInstant")]
    pub can_handle_multiple_set_per_time_instant: Option<String>,
    #[serde(rename = "Real")]
    pub real: Option<TypeAttributes>,
    #[serde(rename = "Integer")]
    pub integer: Option<TypeAttributes>,
    #[serde(rename = "Boolean")]
    pub boolean: Option<TypeAttributes>,
    #[serde(rename = "String")]
    pub string: Option<TypeAttributes>,
    /// Travels as an Integer through fmi2Set/GetInteger (FMI 2.0 section 2.2.7).
    #[serde(rename = "Enumeration")]
    pub enumeration: Option<TypeAttributes>,
}

impl ScalarVariable {
    /// The type element's name and attributes, in the order Real, Integer, Boolean, String,
    /// Enumeration, for every one present (a valid variable has exactly one).
    pub fn types(&self) -> Vec<(&'static str, &TypeAttributes)> {
        [
            ("Real", &self.real),
            ("Integer", &self.integer),
            ("Boolean", &self.boolean),
            ("String", &self.string),
            ("Enumeration", &self.enumeration),
        ]
        .into_iter()
        .filter_map(|(kind, attrs)| attrs.as_ref().map(|a| (kind, a)))
        .collect()
    }
}

fn default_causality() -> String {
    "local".into()
}
fn default_variability() -> String {
    "continuous".into()
}

/// The attributes of a type element (`<Real .../>` and the others; which apply depends on it).
#[derive(Deserialize)]
pub struct TypeAttributes {
    #[serde(rename = "@start")]
    pub start: Option<String>,
    #[serde(rename = "@min")]
    pub min: Option<String>,
    #[serde(rename = "@max")]
    pub max: Option<String>,
    #[serde(rename = "@unit")]
    pub unit: Option<String>,
    #[serde(rename = "@quantity")]
    pub quantity: Option<String>,
    #[serde(rename = "@declaredType")]
    pub declared_type: Option<String>,
    /// A source names the state this variable is the derivative of; a shipped one gives its
    /// 1-based index.
    #[serde(rename = "@derivative")]
    pub derivative: Option<String>,
    #[serde(rename = "@nominal")]
    pub nominal: Option<String>,
    #[serde(rename = "@relativeQuantity")]
    pub relative_quantity: Option<String>,
    #[serde(rename = "@unbounded")]
    pub unbounded: Option<String>,
    #[serde(rename = "@reinit")]
    pub reinit: Option<String>,
}

impl TypeAttributes {
    /// (attribute, value) of every boolean attribute present.
    pub fn flags(&self) -> Vec<(&'static str, &str)> {
        [
            ("relativeQuantity", &self.relative_quantity),
            ("unbounded", &self.unbounded),
            ("reinit", &self.reinit),
        ]
        .into_iter()
        .filter_map(|(key, value)| value.as_deref().map(|v| (key, v)))
        .collect()
    }
}

#[derive(Deserialize, Default)]
pub struct ModelStructure {
    #[serde(rename = "Outputs", default)]
    pub outputs: Unknowns,
    #[serde(rename = "Derivatives", default)]
    pub derivatives: Unknowns,
    #[serde(rename = "InitialUnknowns", default)]
    pub initial_unknowns: Unknowns,
}

impl ModelStructure {
    /// The three lists by name, in the schema's order.
    pub fn lists(&self) -> [(&'static str, &Unknowns); 3] {
        [
            ("Outputs", &self.outputs),
            ("Derivatives", &self.derivatives),
            ("InitialUnknowns", &self.initial_unknowns),
        ]
    }
}

#[derive(Deserialize, Default)]
pub struct Unknowns {
    #[serde(rename = "Unknown", default)]
    pub unknowns: Vec<Unknown>,
}

/// A source names its unknowns and their dependencies
/// (`<Unknown name="force" dependencies="pressure length" .../>`); a shipped description gives
/// 1-based indices (`<Unknown index="3" dependencies="1 2" .../>`).
#[derive(Deserialize)]
pub struct Unknown {
    #[serde(rename = "@index")]
    pub index: Option<String>,
    #[serde(rename = "@name")]
    pub name: Option<String>,
    #[serde(rename = "@dependencies")]
    pub dependencies: Option<String>,
    #[serde(rename = "@dependenciesKind")]
    pub dependencies_kind: Option<String>,
}

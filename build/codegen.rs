//! The Rust code build.rs generates from each checked model description:
//! - `model_tables.rs`, included by `src/variables.rs`: per model, the value references, the
//!   variable metadata and the typed `Parameters`, `Inputs`, `Outputs` and
//!   `CalculatedParameters` structs. It names nothing above the variables module.
//! - `model_bindings.rs`, included by `src/export/registry.rs`: per model, the access by value
//!   reference to those structs' fields, and the registry of every model.

use super::model_description::{field_name, Model, Variable, TYPES};
use std::fmt::Write as _;

#[path = "codegen_arrays.rs"]
mod arrays;
#[path = "codegen_jacobian.rs"]
mod jacobian;

/// `McKibbenMuscle` -> `mckibben_muscle`: a word break comes before a capital that follows a
/// lower-case letter, unless the word so far is a two-letter prefix such as "Mc".
pub fn module_name(s: &str) -> String {
    let mut out = String::new();
    let mut word_len = 0;
    let mut prev_lower = false;
    for ch in s.chars() {
        if ch.is_uppercase() && prev_lower && word_len > 2 {
            out.push('_');
            word_len = 0;
        }
        out.extend(ch.to_lowercase());
        word_len += 1;
        prev_lower = ch.is_lowercase();
    }
    out
}

const KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "dyn", "else", "enum", "extern", "false",
    "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub",
    "ref", "return", "static", "struct", "trait", "true", "type", "unsafe", "use", "where",
    "while", "abstract", "become", "box", "do", "final", "macro", "override", "priv", "try",
    "typeof", "unsized", "virtual", "yield",
];

/// The field identifier of a variable (a raw identifier where the name is a keyword).
fn ident(v: &Variable) -> String {
    let f = field_name(&v.name);
    match f.as_str() {
        "self" | "super" | "crate" => format!("{f}_"),
        _ if KEYWORDS.contains(&f.as_str()) => format!("r#{f}"),
        _ => f,
    }
}

/// `a.b` -> `A_B`, `der(x)` -> `DER_X`.
fn const_name(v: &Variable) -> String {
    let upper: String = v
        .name
        .to_uppercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    upper.trim_end_matches('_').to_string()
}

const RUST_TYPES: [&str; 4] = ["f64", "i32", "bool", "String"];
const ARRAYS: [&str; 4] = ["real", "integer", "boolean", "string"];

/// The four typed groups of a model's variables: (struct name, doc, causality test).
const GROUPS: [(&str, &str, &str); 4] = [
    (
        "Parameters",
        "The parameters (fixed or tunable); `Default` gives the start values.",
        "parameter",
    ),
    (
        "Inputs",
        "The inputs; `Default` gives the start values.",
        "input",
    ),
    (
        "Outputs",
        "The outputs; `Default` gives zero (or the start value where one is declared).",
        "output",
    ),
    (
        "CalculatedParameters",
        "The calculated parameters, which a model computes from its parameters when it is built.",
        "calculatedParameter",
    ),
];

fn literal(v: &Variable, value: Option<&str>) -> Result<String, String> {
    Ok(match (v.type_index, value) {
        (0, None) => "0.0".into(),
        (1, None) => "0".into(),
        (2, None) => "false".into(),
        (_, None) => "String::new()".into(),
        (0, Some(s)) => real_literal(s)?,
        (1, Some(s)) => s
            .trim()
            .parse::<i32>()
            .map_err(|e| format!("bad start '{s}': {e}"))?
            .to_string(),
        (2, Some(s)) => parse_bool(s)?.to_string(),
        (_, Some(s)) => format!("String::from({s:?})"),
    })
}

/// Appends the tables and typed structs of `model` to `code` (`model_tables.rs`).
pub fn tables(model: &Model, xml_path: &str, code: &mut String) -> Result<(), String> {
    let stem = &model.name;
    let module = module_name(stem);
    let _ = writeln!(
        code,
        "/// Variables of `{stem}`, from modelDescription/{stem}.xml."
    );
    let _ = writeln!(code, "pub mod {module} {{");
    let _ = writeln!(code, "    use crate::variables::*;");
    for (t, type_name) in TYPES.iter().enumerate() {
        let _ = writeln!(
            code,
            "    /// Value references (array indices) of the {type_name} variables."
        );
        let _ = writeln!(code, "    #[allow(dead_code)]");
        let _ = writeln!(code, "    pub mod {} {{", ARRAYS[t]);
        for v in model.variables.iter().filter(|v| v.type_index == t) {
            let _ = writeln!(code, "        /// {}", v.description);
            let _ = writeln!(
                code,
                "        pub const {}: usize = {};",
                const_name(v),
                v.value_reference
            );
        }
        let _ = writeln!(code, "    }}");
    }
    let _ = writeln!(code, "    pub static VARIABLES: &[Variable] = &[");
    for v in &model.variables {
        let start = match (v.type_index, &v.start) {
            (_, None) => "Start::None".to_string(),
            (3, Some(s)) => format!("Start::String({s:?})"),
            (t, Some(s)) => format!("Start::{}({})", TYPES[t], literal(v, Some(s))?),
        };
        let bound = |b: &Option<String>| -> Result<String, String> {
            Ok(match b {
                None => "None".into(),
                Some(s) if v.type_index == 0 => format!("Some({})", real_literal(s)?),
                Some(s) => format!(
                    "Some({}.0)",
                    s.trim()
                        .parse::<i64>()
                        .map_err(|e| format!("bad bound '{s}': {e}"))?
                ),
            })
        };
        let _ = writeln!(
            code,
            "        Variable {{ name: {:?}, kind: VarType::{}, vr: {}, causality: Causality::{}, variability: Variability::{}, initial: Initial::{}, start: {start}, min: {}, max: {}, unit: {:?}, description: {:?} }},",
            v.name,
            TYPES[v.type_index],
            v.value_reference,
            capitalize(&v.causality),
            capitalize(&v.variability),
            capitalize(v.initial),
            bound(&v.min)?,
            bound(&v.max)?,
            v.unit.clone().unwrap_or_default(),
            v.description,
        );
    }
    let _ = writeln!(code, "    ];");
    let _ = writeln!(code, "    pub static INFO: ModelInfo = ModelInfo {{");
    let _ = writeln!(code, "        name: {stem:?},");
    let _ = writeln!(code, "        guid: {:?},", model.guid);
    let _ = writeln!(code, "        description: {:?},", model.description);
    let _ = writeln!(
        code,
        "        model_description_xml: include_str!({xml_path:?}),"
    );
    let _ = writeln!(code, "        variables: VARIABLES,");
    let _ = writeln!(code, "        counts: {:?},", model.counts);
    let _ = writeln!(code, "        log_categories: LOG_CATEGORIES,");
    let _ = writeln!(code, "    }};");

    for (name, doc, causality) in GROUPS {
        let _ = writeln!(code, "    /// {doc}");
        let _ = writeln!(
            code,
            "    #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]"
        );
        let _ = writeln!(code, "    pub struct {name} {{");
        let members: Vec<&Variable> = model
            .variables
            .iter()
            .filter(|v| v.causality == causality)
            .collect();
        for v in &members {
            let unit = match v.unit.as_deref() {
                Some(u) if u != "1" => format!(" ({u})"),
                _ => String::new(),
            };
            let _ = writeln!(code, "        /// {}{unit}", v.description);
            let _ = writeln!(
                code,
                "        pub {}: {},",
                ident(v),
                RUST_TYPES[v.type_index]
            );
        }
        let _ = writeln!(code, "    }}");
        let _ = writeln!(code, "    #[allow(clippy::derivable_impls)]");
        let _ = writeln!(code, "    impl Default for {name} {{");
        let _ = writeln!(code, "        fn default() -> Self {{");
        let _ = writeln!(code, "            Self {{");
        for v in &members {
            let _ = writeln!(
                code,
                "                {}: {},",
                ident(v),
                literal(v, v.start.as_deref())?
            );
        }
        let _ = writeln!(code, "            }}");
        let _ = writeln!(code, "        }}");
        let _ = writeln!(code, "    }}");
    }
    states(model, code)?;
    jacobian::identifiers(model, code)?;
    jacobian::identical(model, code);
    arrays::identifiers(model, code)?;
    let _ = writeln!(
        code,
        "    /// The interface of `{stem}`: its typed variable groups and metadata."
    );
    let _ = writeln!(code, "    pub struct Variables;");
    let _ = writeln!(code, "    impl Interface for Variables {{");
    for (name, _, _) in GROUPS {
        let _ = writeln!(code, "        type {name} = {name};");
    }
    let _ = writeln!(code, "        type States = States;");
    let _ = writeln!(code, "        type Known = Known;");
    let _ = writeln!(code, "        type Unknown = Unknown;");
    let _ = writeln!(code, "        type ArrayOutput = ArrayOutput;");
    let _ = writeln!(
        code,
        "        const EVENT_INDICATORS: usize = {};",
        model.event_indicators
    );
    let _ = writeln!(code, "        const INFO: &'static ModelInfo = &INFO;");
    let _ = writeln!(code, "    }}");
    let _ = writeln!(code, "}}\n");
    Ok(())
}

/// The `States` struct of a model (named fields in state-vector order, also used for the
/// derivatives) and its [`ContinuousStates`] implementation; an empty struct without states.
fn states(model: &Model, code: &mut String) -> Result<(), String> {
    let n = model.states.len();
    let vars = &model.variables;
    let _ = writeln!(
        code,
        "    /// The continuous states, in the order of <ModelStructure><Derivatives>; the same struct holds their derivatives."
    );
    let _ = writeln!(
        code,
        "    #[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]"
    );
    let _ = writeln!(code, "    pub struct States {{");
    for &(s, _) in &model.states {
        let v = &vars[s];
        let unit = v.unit.as_deref().unwrap_or("1");
        let _ = writeln!(code, "        /// {} ({unit})", v.description);
        let _ = writeln!(code, "        pub {}: f64,", ident(v));
    }
    let _ = writeln!(code, "    }}");
    let names = |which: fn(&(usize, usize)) -> usize| -> Vec<&str> {
        model
            .states
            .iter()
            .map(|p| vars[which(p)].name.as_str())
            .collect()
    };
    let vrs = |which: fn(&(usize, usize)) -> usize| -> Vec<u32> {
        model
            .states
            .iter()
            .map(|p| vars[which(p)].value_reference)
            .collect()
    };
    let nominals = model
        .states
        .iter()
        .map(|&(s, _)| real_literal(vars[s].nominal.as_deref().unwrap_or("1")))
        .collect::<Result<Vec<_>, _>>()?;
    let fields: Vec<String> = model.states.iter().map(|&(s, _)| ident(&vars[s])).collect();
    let _ = writeln!(code, "    #[allow(unused_variables)]");
    let _ = writeln!(code, "    impl ContinuousStates for States {{");
    let _ = writeln!(code, "        const COUNT: usize = {n};");
    let _ = writeln!(
        code,
        "        const NAMES: &'static [&'static str] = &{:?};",
        names(|p| p.0)
    );
    let _ = writeln!(
        code,
        "        const DERIVATIVE_NAMES: &'static [&'static str] = &{:?};",
        names(|p| p.1)
    );
    let _ = writeln!(
        code,
        "        const VALUE_REFERENCES: &'static [u32] = &{:?};",
        vrs(|p| p.0)
    );
    let _ = writeln!(
        code,
        "        const DERIVATIVE_VALUE_REFERENCES: &'static [u32] = &{:?};",
        vrs(|p| p.1)
    );
    let _ = writeln!(
        code,
        "        const NOMINALS: &'static [f64] = &[{}];",
        nominals.join(", ")
    );
    let _ = writeln!(code, "        #[inline]");
    let _ = writeln!(code, "        fn from_slice(x: &[f64]) -> Self {{");
    let _ = writeln!(code, "            Self {{");
    for (i, f) in fields.iter().enumerate() {
        let _ = writeln!(code, "                {f}: x[{i}],");
    }
    let _ = writeln!(code, "            }}");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "        #[inline]");
    let _ = writeln!(code, "        fn write_to(&self, x: &mut [f64]) {{");
    for (i, f) in fields.iter().enumerate() {
        let _ = writeln!(code, "            x[{i}] = self.{f};");
    }
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
    let _ = writeln!(code, "    impl From<[f64; {n}]> for States {{");
    let _ = writeln!(code, "        fn from(x: [f64; {n}]) -> Self {{");
    let _ = writeln!(code, "            Self::from_slice(&x)");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
    let _ = writeln!(code, "    impl From<States> for [f64; {n}] {{");
    let _ = writeln!(code, "        fn from(s: States) -> Self {{");
    let _ = writeln!(code, "            let mut x = [0.0; {n}];");
    let _ = writeln!(code, "            s.write_to(&mut x);");
    let _ = writeln!(code, "            x");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
    Ok(())
}

/// The place in the export layer's `Values` that holds variable `i`: its causality's group, or
/// for a local the state mirror or the derivatives (by the state's field).
fn place(model: &Model, i: usize) -> Result<(&'static str, String), String> {
    let v = &model.variables[i];
    let group = match v.causality.as_str() {
        "parameter" => "parameters",
        "input" => "inputs",
        "output" => "outputs",
        "calculatedParameter" => "calculated",
        "local" => {
            if let Some(&(s, _)) = model.states.iter().find(|&&(_, d)| d == i) {
                return Ok(("derivatives", ident(&model.variables[s])));
            }
            "states"
        }
        other => {
            return Err(format!(
                "causality '{other}' has no typed group (parameter, calculatedParameter, input, output, local state or derivative)"
            ))
        }
    };
    Ok((group, ident(v)))
}

/// Appends the export layer's access by value reference to the typed values of `model`
/// (`model_bindings.rs`): per type, one `match` from value reference to field; for more than a
/// few Reals with value references 0..n, a table of field offsets instead.
pub fn bindings(model: &Model, code: &mut String) -> Result<(), String> {
    let module = module_name(&model.name);
    let real_arms = arms_of(model, 0)?;
    // Models with many Reals read and write them through a table of field offsets, one lookup
    // whatever their number (the ideal McKibben's step measured 22.7 ns with it against 26.0 ns
    // with a `match`, benches/parity.rs); a few Reals need no table.
    let by_offset = real_arms.len() > 4 && dense(&real_arms);
    if by_offset {
        real_offsets(&module, &real_arms, code);
    }
    let _ = writeln!(
        code,
        "#[allow(unused_variables, clippy::single_match, clippy::match_single_binding)]"
    );
    let _ = writeln!(
        code,
        "impl Bindings for crate::variables::{module}::Variables {{"
    );
    for (t, array) in ARRAYS.iter().enumerate() {
        let rust = RUST_TYPES[t];
        // An unknown Real reads as NaN (see `Bindings::real`).
        let (get_type, default, set_type) = match t {
            0 => (rust, "f64::NAN", rust),
            3 => ("&str", "\"\"", "&str"),
            _ => (rust, "Default::default()", rust),
        };
        let arms = arms_of(model, t)?;
        if t == 0 && by_offset {
            real_by_offset(&module, code);
            continue;
        }
        let _ = writeln!(code, "    #[inline]");
        let _ = writeln!(
            code,
            "    fn {array}(values: &Values<Self>, vr: usize) -> {get_type} {{"
        );
        let _ = writeln!(code, "        match vr {{");
        for (vr, g, f) in &arms {
            let read = if t == 3 {
                format!("values.{g}.{f}.as_str()")
            } else {
                format!("values.{g}.{f}")
            };
            let _ = writeln!(code, "            {vr} => {read},");
        }
        let _ = writeln!(code, "            _ => {default},");
        let _ = writeln!(code, "        }}");
        let _ = writeln!(code, "    }}");
        let _ = writeln!(code, "    #[inline]");
        let _ = writeln!(
            code,
            "    fn set_{array}(values: &mut Values<Self>, vr: usize, value: {set_type}) {{"
        );
        let _ = writeln!(code, "        match vr {{");
        for (vr, g, f) in &arms {
            let write = if t == 3 {
                format!("values.{g}.{f} = value.to_string()")
            } else {
                format!("values.{g}.{f} = value")
            };
            let _ = writeln!(code, "            {vr} => {write},");
        }
        let _ = writeln!(code, "            _ => {{}}");
        let _ = writeln!(code, "        }}");
        let _ = writeln!(code, "    }}");
    }
    // The out-of-range flag (`src/export/instance/out_of_range.rs`) written by its field: every
    // model that clamps has it, under the same name.
    let flag = arms_of(model, 2)?
        .into_iter()
        .find(|(_, g, f)| *g == "outputs" && f == "input_clamped")
        .map_or(String::new(), |(_, g, f)| {
            format!("values.{g}.{f} = value;")
        });
    let _ = writeln!(code, "    #[inline]");
    let _ = writeln!(
        code,
        "    fn set_input_clamped(values: &mut Values<Self>, value: bool) {{ {flag} }}"
    );
    let _ = writeln!(code, "}}\n");
    Ok(())
}

/// The variables of type `t` (an index of ARRAYS): value reference, group and field.
fn arms_of(model: &Model, t: usize) -> Result<Vec<(u32, &'static str, String)>, String> {
    let mut arms = Vec::new();
    for (i, v) in model.variables.iter().enumerate() {
        if v.type_index == t {
            let (g, f) = place(model, i)?;
            arms.push((v.value_reference, g, f));
        }
    }
    arms.sort_by_key(|a| a.0);
    Ok(arms)
}

/// Whether the value references of `arms` (sorted) are exactly 0..n.
fn dense(arms: &[(u32, &'static str, String)]) -> bool {
    arms.iter().enumerate().all(|(i, a)| a.0 as usize == i)
}

/// The offset of each Real variable's field in `Values`, indexed by value reference, for
/// [`real_by_offset`]; and a never-called function that fails to compile unless every one of
/// those fields is an `f64`, which the reads and writes through the offsets rely on.
fn real_offsets(module: &str, arms: &[(u32, &'static str, String)], code: &mut String) {
    let values = format!("Values<crate::variables::{module}::Variables>");
    let upper = module.to_uppercase();
    let n = arms.len();
    let _ = writeln!(
        code,
        "/// {module}: the offset in `Values` of each Real variable's field, by value reference."
    );
    let _ = writeln!(code, "const REAL_OFFSETS_{upper}: [usize; {n}] = [");
    for (_, g, f) in arms {
        let _ = writeln!(code, "    core::mem::offset_of!({values}, {g}.{f}),");
    }
    let _ = writeln!(code, "];\n");
    let _ = writeln!(
        code,
        "/// Compiles only if every field behind REAL_OFFSETS_{upper} is an f64."
    );
    let _ = writeln!(code, "#[allow(dead_code)]");
    let _ = writeln!(
        code,
        "fn real_fields_of_{module}_are_f64(values: &{values}) -> [&f64; {n}] {{"
    );
    let fields: Vec<String> = arms
        .iter()
        .map(|(_, g, f)| format!("&values.{g}.{f}"))
        .collect();
    let _ = writeln!(code, "    [{}]", fields.join(", "));
    let _ = writeln!(code, "}}\n");
}

/// `real`/`set_real` through the offsets of [`real_offsets`]: a load of the offset and one of the
/// value.
fn real_by_offset(module: &str, code: &mut String) {
    let table = format!("REAL_OFFSETS_{}", module.to_uppercase());
    let safety = "// SAFETY: the offset of an f64 field of Values<Self> (offset_of!; the fields' \
                  type is checked by real_fields_of_*_are_f64).";
    let _ = writeln!(code, "    #[inline]");
    let _ = writeln!(
        code,
        "    fn real(values: &Values<Self>, vr: usize) -> f64 {{"
    );
    let _ = writeln!(code, "        match {table}.get(vr) {{");
    let _ = writeln!(code, "            {safety}");
    let _ = writeln!(
        code,
        "            Some(&offset) => unsafe {{ (values as *const Values<Self>).cast::<u8>().add(offset).cast::<f64>().read() }},"
    );
    let _ = writeln!(code, "            None => f64::NAN,");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
    let _ = writeln!(code, "    #[inline]");
    let _ = writeln!(
        code,
        "    fn set_real(values: &mut Values<Self>, vr: usize, value: f64) {{"
    );
    let _ = writeln!(code, "        if let Some(&offset) = {table}.get(vr) {{");
    let _ = writeln!(code, "            {safety}");
    let _ = writeln!(
        code,
        "            unsafe {{ (values as *mut Values<Self>).cast::<u8>().add(offset).cast::<f64>().write(value) }}"
    );
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
}

/// The registry: one factory per model, the model type named after the description.
pub fn registry(models: &[Model], code: &mut String) {
    code.push_str("/// Every model of the crate, as generated from modelDescription/.\n");
    code.push_str("pub static REGISTRY: &[&dyn Factory] = &[\n");
    for m in models {
        let _ = writeln!(
            code,
            "    &ModelFactory::<crate::models::{}::{}>::NEW,",
            module_name(&m.name),
            m.name
        );
    }
    code.push_str("];\n");
}

fn real_literal(s: &str) -> Result<String, String> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|e| format!("bad number '{s}': {e}"))?;
    if !x.is_finite() {
        return Err(format!("'{s}' is not finite"));
    }
    Ok(format!("{x:?}"))
}

fn parse_bool(s: &str) -> Result<bool, String> {
    match s.trim() {
        "true" | "1" => Ok(true),
        "false" | "0" => Ok(false),
        _ => Err(format!("bad Boolean '{s}'")),
    }
}

fn capitalize(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().collect::<String>() + c.as_str())
        .unwrap_or_default()
}

//! The identifiers of each model's Jacobian, appended to `model_tables.rs` by
//! [`super::tables`]: `Known` and `Unknown`, one variant per variable, with the map from value
//! reference to identifier the export layer uses, and the bitwise comparison of the inputs that
//! its partials cache keys on.

use super::{ident, Model, Variable};
use std::fmt::Write as _;

/// [`Identical`] for the inputs: Reals compared bit for bit (`-0.0` is not `0.0`, NaN is NaN), so
/// that partials cached at some inputs are reused only at exactly those.
pub fn identical(model: &Model, code: &mut String) {
    let tests: Vec<String> = model
        .variables
        .iter()
        .filter(|v| v.causality == "input")
        .map(|v| match v.type_index {
            0 => format!("self.{0}.to_bits() == other.{0}.to_bits()", ident(v)),
            _ => format!("self.{0} == other.{0}", ident(v)),
        })
        .collect();
    let all = if tests.is_empty() {
        "true".to_string()
    } else {
        tests.join(" && ")
    };
    let _ = writeln!(code, "    impl Identical for Inputs {{");
    let _ = writeln!(code, "        #[inline]");
    let _ = writeln!(
        code,
        "        fn identical(&self, other: &Self) -> bool {{ let _ = other; {all} }}"
    );
    let _ = writeln!(code, "    }}");
}

/// `der(joint_angle)` -> `DerJointAngle`, `jointTorque` -> `JointTorque`: a variable's name as an
/// enum variant.
fn variant_name(v: &Variable) -> String {
    let mut out = String::new();
    let mut capital = true;
    for ch in v.name.chars() {
        if !ch.is_ascii_alphanumeric() {
            capital = true;
        } else if capital {
            out.extend(ch.to_uppercase());
            capital = false;
        } else {
            out.push(ch);
        }
    }
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, 'V');
    }
    if out == "Self" {
        out.push('_');
    }
    out
}

/// The identifiers of a model's Jacobian: `Known` (the Real inputs, then the continuous states)
/// and `Unknown` (the Real outputs, then the state derivatives), each with the map from value
/// reference to identifier the export layer uses.
pub fn identifiers(model: &Model, code: &mut String) -> Result<(), String> {
    let vars = &model.variables;
    let real_with = |causality: &'static str| {
        vars.iter()
            .filter(move |v| v.type_index == 0 && v.causality == causality)
    };
    let known: Vec<&Variable> = real_with("input")
        .chain(model.states.iter().map(|&(s, _)| &vars[s]))
        .collect();
    let unknown: Vec<&Variable> = real_with("output")
        .chain(model.states.iter().map(|&(_, d)| &vars[d]))
        .collect();
    identifier_enum(
        "Known",
        "The knowns of the model's Jacobian (`fmi2GetDirectionalDerivative`'s `vKnown_ref`): the Real inputs, then the continuous states.",
        &known,
        code,
    )?;
    identifier_enum(
        "Unknown",
        "The unknowns of the model's Jacobian (`vUnknown_ref`): the Real outputs, then the state derivatives.",
        &unknown,
        code,
    )
}

fn identifier_enum(
    name: &str,
    doc: &str,
    members: &[&Variable],
    code: &mut String,
) -> Result<(), String> {
    let variants: Vec<String> = members.iter().map(|v| variant_name(v)).collect();
    for (i, a) in variants.iter().enumerate() {
        if let Some(j) = variants[..i].iter().position(|b| b == a) {
            return Err(format!(
                "'{}' and '{}' both become {name}::{a}: rename one",
                members[j].name, members[i].name
            ));
        }
    }
    let _ = writeln!(code, "    /// {doc}");
    let _ = writeln!(
        code,
        "    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]"
    );
    let _ = writeln!(code, "    pub enum {name} {{");
    for (v, variant) in members.iter().zip(&variants) {
        let _ = writeln!(code, "        /// `{}`: {}", v.name, v.description);
        let _ = writeln!(code, "        {variant},");
    }
    let _ = writeln!(code, "    }}");
    let _ = writeln!(code, "    impl Identifier for {name} {{");
    let all: Vec<String> = variants.iter().map(|v| format!("Self::{v}")).collect();
    let _ = writeln!(
        code,
        "        const ALL: &'static [Self] = &[{}];",
        all.join(", ")
    );
    let _ = writeln!(code, "        #[inline]");
    let _ = writeln!(code, "        fn index(self) -> usize {{");
    let _ = writeln!(code, "            match self {{");
    for (i, variant) in variants.iter().enumerate() {
        let _ = writeln!(code, "                Self::{variant} => {i},");
    }
    let _ = writeln!(code, "            }}");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "        #[inline]");
    let _ = writeln!(
        code,
        "        fn from_value_reference(vr: u32) -> Option<Self> {{"
    );
    let _ = writeln!(code, "            match vr {{");
    for (v, variant) in members.iter().zip(&variants) {
        let _ = writeln!(
            code,
            "                {} => Some(Self::{variant}),",
            v.value_reference
        );
    }
    let _ = writeln!(code, "                _ => None,");
    let _ = writeln!(code, "            }}");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
    Ok(())
}

//! The identifiers of each model's Jacobian, appended to `model_tables.rs` by
//! [`super::tables`]: `Known` and `Unknown`, one variant per variable, with the map from value
//! reference to identifier the export layer uses; one row type per unknown whose fields are the
//! knowns its `<ModelStructure>` entry declares, so that a model's partials hold to the declared
//! dependencies by construction; and the bitwise comparison of the inputs that its partials cache
//! keys on.

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

/// `der(joint_angle)` -> `DerJointAngle`, `jointTorque` -> `JointTorque`: a variable's (or an
/// array's) name as an enum variant.
pub(super) fn variant_name(name: &str) -> String {
    let mut out = String::new();
    let mut capital = true;
    for ch in name.chars() {
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
    )?;
    for u in &unknown {
        row_type(model, u, &known, code)?;
    }
    Ok(())
}

/// The row type of unknown `u`: `ForceBy { pressure, length }`, one field per Real known its
/// `<ModelStructure>` entry (Outputs or Derivatives) declares, in `Known` order; every known when
/// the entry lists no `dependencies` (FMI 2.0: then it depends on all). A model writes its row
/// only through it: an undeclared partial and a missing declared one are compile errors.
fn row_type(
    model: &Model,
    u: &Variable,
    known: &[&Variable],
    code: &mut String,
) -> Result<(), String> {
    let vars = &model.variables;
    let index = vars
        .iter()
        .position(|v| std::ptr::eq(v, u))
        .ok_or("an unknown that is not a variable")?;
    let entry = model
        .outputs
        .iter()
        .chain(&model.derivatives)
        .find(|r| r.index == index + 1)
        .ok_or_else(|| format!("'{}' has no <ModelStructure> entry", u.name))?;
    let declared: Vec<&Variable> = known
        .iter()
        .copied()
        .filter(|k| match &entry.dependencies {
            None => true,
            Some(deps) => deps.iter().any(|&d| std::ptr::eq(&vars[d - 1], *k)),
        })
        .collect();
    let unknown = variant_name(&u.name);
    let name = format!("{unknown}By");
    let _ = writeln!(
        code,
        "    /// The row of `{}` in the Jacobian: its partial derivative by each known its \
         `<ModelStructure>` entry declares, and by no other.",
        u.name
    );
    let _ = writeln!(code, "    #[derive(Clone, Copy, Debug, PartialEq)]");
    let _ = writeln!(code, "    pub struct {name} {{");
    for k in &declared {
        let _ = writeln!(code, "        /// `d {} / d {}`", u.name, k.name);
        let _ = writeln!(code, "        pub {}: f64,", ident(k));
    }
    let _ = writeln!(code, "    }}");
    let _ = writeln!(code, "    impl Row for {name} {{");
    let _ = writeln!(code, "        type Variables = Variables;");
    let _ = writeln!(code, "        const UNKNOWN: Unknown = Unknown::{unknown};");
    let knowns: Vec<String> = declared
        .iter()
        .map(|k| format!("Known::{}", variant_name(&k.name)))
        .collect();
    let _ = writeln!(
        code,
        "        const KNOWNS: &'static [Known] = &[{}];",
        knowns.join(", ")
    );
    let _ = writeln!(code, "        #[inline]");
    let _ = writeln!(
        code,
        "        fn from_fn(mut by: impl FnMut(Known) -> f64) -> Self {{"
    );
    let _ = writeln!(code, "            let _ = &mut by;");
    let _ = writeln!(code, "            Self {{");
    for (k, known) in declared.iter().zip(&knowns) {
        let _ = writeln!(code, "                {}: by({known}),", ident(k));
    }
    let _ = writeln!(code, "            }}");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "        #[inline]");
    let _ = writeln!(
        code,
        "        fn write(&self, mut into: impl FnMut(Known, f64)) {{"
    );
    let _ = writeln!(code, "            let _ = &mut into;");
    for (k, known) in declared.iter().zip(&knowns) {
        let _ = writeln!(code, "            into({known}, self.{});", ident(k));
    }
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
    Ok(())
}

fn identifier_enum(
    name: &str,
    doc: &str,
    members: &[&Variable],
    code: &mut String,
) -> Result<(), String> {
    let variants: Vec<String> = members.iter().map(|v| variant_name(&v.name)).collect();
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

//! The identifiers of each model's FMI 3.0 array outputs, appended to `model_tables.rs` by
//! [`super::tables`]: `ArrayOutput`, one variant per `<Array>` the source's VendorAnnotations
//! declare (none: an empty enum), so that a model computes its arrays against a type and a
//! renamed array is a compile error in the model.

use super::jacobian::variant_name;
use super::Model;
use std::fmt::Write as _;

/// `ArrayOutput` of `model` and its [`ArrayIdentifier`] implementation (declaration order, which
/// is the order of the FMI 3.0 value references).
pub fn identifiers(model: &Model, code: &mut String) -> Result<(), String> {
    let arrays: Vec<_> = model.source.arrays().collect();
    let variants: Vec<String> = arrays.iter().map(|a| variant_name(&a.name)).collect();
    for (i, a) in variants.iter().enumerate() {
        if let Some(j) = variants[..i].iter().position(|b| b == a) {
            return Err(format!(
                "arrays '{}' and '{}' both become ArrayOutput::{a}: rename one",
                arrays[j].name, arrays[i].name
            ));
        }
    }
    let _ = writeln!(
        code,
        "    /// The FMI 3.0 array outputs (`<Arrays>` of the model description's VendorAnnotations)."
    );
    let _ = writeln!(code, "    #[derive(Clone, Copy, Debug, PartialEq, Eq)]");
    let _ = writeln!(code, "    pub enum ArrayOutput {{");
    for (a, variant) in arrays.iter().zip(&variants) {
        let description = a.description.as_deref().unwrap_or_default();
        let _ = writeln!(code, "        /// `{}`: {description}", a.name);
        let _ = writeln!(code, "        {variant},");
    }
    let _ = writeln!(code, "    }}");
    let all: Vec<String> = variants.iter().map(|v| format!("Self::{v}")).collect();
    let _ = writeln!(code, "    impl ArrayIdentifier for ArrayOutput {{");
    let _ = writeln!(
        code,
        "        const ALL: &'static [Self] = &[{}];",
        all.join(", ")
    );
    let _ = writeln!(code, "        fn name(self) -> &'static str {{");
    let _ = writeln!(code, "            match self {{");
    for (a, variant) in arrays.iter().zip(&variants) {
        let _ = writeln!(code, "                Self::{variant} => {:?},", a.name);
    }
    let _ = writeln!(code, "            }}");
    let _ = writeln!(code, "        }}");
    let _ = writeln!(code, "    }}");
    Ok(())
}

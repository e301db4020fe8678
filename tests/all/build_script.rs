//! The build script's modules (`build/`), compiled once for the tests that check them: they name
//! each other as siblings (`super::model_description`), so they live side by side here.

#![allow(dead_code)]

#[path = "../../build/codegen.rs"]
pub mod codegen;
#[path = "../../build/fmi3_description.rs"]
pub mod fmi3_description;
#[path = "../../build/model_description.rs"]
pub mod model_description;
#[path = "../../build/terminals.rs"]
pub mod terminals;

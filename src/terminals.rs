//! The FMI 3.0 `terminalsAndIcons/terminalsAndIcons.xml` of each model that declares mechanical
//! flanges in its `modelDescription/<Model>.xml`, generated and checked by build.rs
//! (`build/terminals.rs`). The FMI 3.0 packager writes them into the FMUs; the FMU code never
//! reads them.

include!(concat!(env!("OUT_DIR"), "/terminals.rs"));

/// The terminalsAndIcons.xml of `model`, if it declares any flange.
pub fn terminals_and_icons(model: &str) -> Option<&'static str> {
    TERMINALS_AND_ICONS
        .iter()
        .find(|(name, _)| *name == model)
        .map(|(_, xml)| *xml)
}

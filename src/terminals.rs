//! The FMI 3.0 `terminalsAndIcons/terminalsAndIcons.xml` of each model: its icon's placement, and
//! a terminal for each mechanical flange its `modelDescription/<Model>.xml` declares, generated
//! and checked by build.rs (`build/terminals.rs`). The FMI 3.0 packager writes them into the FMUs
//! with the icons (`tools/src/icons.rs`); the FMU code never reads them.

include!(concat!(env!("OUT_DIR"), "/terminals.rs"));

/// The terminalsAndIcons.xml of `model` (`None` for a name that is no model).
pub fn terminals_and_icons(model: &str) -> Option<&'static str> {
    TERMINALS_AND_ICONS
        .iter()
        .find(|(name, _)| *name == model)
        .map(|(_, xml)| *xml)
}

//! The shipped description: the source with the export layer's parts spliced in at byte offsets
//! (capabilities, log categories, an index comment before each variable, the ModelStructure with
//! 1-based indices).

use super::{
    ResolvedUnknown, Variable, CO_SIMULATION_CAPABILITIES, LOG_CATEGORIES,
    MODEL_EXCHANGE_CAPABILITIES,
};
use std::fmt::Write as _;

/// Byte offsets in the source where the export layer's parts go.
#[derive(Default)]
struct Splices {
    /// Right after the `<fmiModelDescription ...>` start tag.
    after_root: usize,
    /// Before the first of DefaultExperiment, VendorAnnotations, ModelVariables.
    log_categories: Option<usize>,
    /// Before each ScalarVariable.
    variables: Vec<usize>,
    /// The source's ModelStructure element, start and end.
    model_structure: Option<(usize, usize)>,
    /// The source's FMI 3.0-only `<Tool>` elements, `<Terminals>` (the flanges,
    /// `build/terminals.rs`) and `<Arrays>` (`build/fmi3_description.rs`), each from the start of
    /// its line: FMI 2.0's schema allows a Tool one element, its `<Tests>`.
    fmi3_only: Vec<(usize, usize)>,
}

fn find_splices(text: &str) -> Result<Splices, String> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    let mut splices = Splices::default();
    let mut depth = 0usize;
    let mut structure_start = None;
    let mut terminals_start = None;
    loop {
        let before = reader.buffer_position() as usize;
        let event = reader
            .read_event()
            .map_err(|e| format!("cannot parse: {e}"))?;
        let after = reader.buffer_position() as usize;
        let (name, empty) = match &event {
            Event::Start(e) => (e.local_name().as_ref().to_vec(), false),
            Event::Empty(e) => (e.local_name().as_ref().to_vec(), true),
            Event::End(_) => {
                depth -= 1;
                if depth == 1 {
                    if let Some(start) = structure_start.take() {
                        splices.model_structure = Some((start, after));
                    }
                }
                if depth == 3 {
                    if let Some(start) = terminals_start.take() {
                        splices.fmi3_only.push((start, after));
                    }
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        match (depth, name.as_slice()) {
            (0, b"fmiModelDescription") => splices.after_root = after,
            (1, b"DefaultExperiment" | b"VendorAnnotations" | b"ModelVariables") => {
                splices.log_categories.get_or_insert(before);
            }
            (1, b"ModelStructure") if empty => splices.model_structure = Some((before, after)),
            (1, b"ModelStructure") => structure_start = Some(before),
            (3, b"Terminals" | b"Arrays") => {
                let line = text[..before].rfind('\n').unwrap_or(before);
                if empty {
                    splices.fmi3_only.push((line, after));
                } else {
                    terminals_start = Some(line);
                }
            }
            (2, b"ScalarVariable") => splices.variables.push(before),
            _ => {}
        }
        if !empty {
            depth += 1;
        }
    }
    Ok(splices)
}

/// The model description as shipped (GUID still the placeholder): the source with the export
/// layer's `<CoSimulation>` and `<LogCategories>`, an index comment before each variable, and the
/// ModelStructure with 1-based indices.
pub(super) fn shipped(
    text: &str,
    stem: &str,
    variables: &[Variable],
    states: &[(usize, usize)],
    lists: &[(&str, &[ResolvedUnknown])],
) -> Result<String, String> {
    let s = find_splices(text)?;
    // Every model serves both interfaces and its exact partials: the registry's test
    // (`src/export/registry.rs`) checks each model against this, so that no list names them.
    let mut inserts: Vec<(usize, usize, String)> = Vec::new();
    inserts.push((
        s.after_root,
        s.after_root,
        format!(
            "\n\n  <!-- Written by build.rs: the export layer's capabilities. -->\n  <ModelExchange\n    modelIdentifier=\"{stem}\"\n    {MODEL_EXCHANGE_CAPABILITIES}\n    providesDirectionalDerivative=\"true\"/>\n  <CoSimulation\n    modelIdentifier=\"{stem}\"\n    {CO_SIMULATION_CAPABILITIES}\n    providesDirectionalDerivative=\"true\"/>"
        ),
    ));
    let mut log = String::from("<LogCategories>\n");
    for (name, description) in LOG_CATEGORIES {
        let _ = writeln!(
            log,
            "    <Category name=\"{name}\" description=\"{description}\"/>"
        );
    }
    log.push_str("  </LogCategories>\n\n  ");
    let at = s.log_categories.ok_or("no ModelVariables element found")?;
    inserts.push((at, at, log));
    for &(start, end) in &s.fmi3_only {
        inserts.push((start, end, String::new()));
    }
    for (i, &at) in s.variables.iter().enumerate() {
        inserts.push((at, at, format!("<!-- {} -->", i + 1)));
    }
    let mut structure = String::from("<ModelStructure>\n");
    for &(list, unknowns) in lists {
        if unknowns.is_empty() {
            continue;
        }
        let _ = writeln!(structure, "    <{list}>");
        for u in unknowns {
            let mut attributes = format!("index=\"{}\"", u.index);
            if let Some(d) = &u.dependencies {
                let d: Vec<String> = d.iter().map(|i| i.to_string()).collect();
                let _ = write!(attributes, " dependencies=\"{}\"", d.join(" "));
            }
            if let Some(k) = &u.kinds {
                let _ = write!(attributes, " dependenciesKind=\"{}\"", k.join(" "));
            }
            let _ = writeln!(
                structure,
                "      <Unknown {attributes}/> <!-- {} -->",
                variables[u.index - 1].name
            );
        }
        let _ = writeln!(structure, "    </{list}>");
    }
    structure.push_str("  </ModelStructure>");
    match s.model_structure {
        Some((start, end)) => inserts.push((start, end, structure)),
        None => {
            // No ModelStructure in the source: it goes before the closing root tag.
            let end = text
                .rfind("</fmiModelDescription>")
                .ok_or("no closing </fmiModelDescription>")?;
            inserts.push((end, end, format!("\n  {structure}\n")));
        }
    }
    inserts.sort_by_key(|(start, _, _)| *start);
    let mut out = String::with_capacity(text.len() + 4096);
    let mut cursor = 0;
    for (start, end, insert) in inserts {
        out.push_str(&text[cursor..start]);
        out.push_str(&insert);
        cursor = end;
    }
    out.push_str(&text[cursor..]);
    // Each derivative names its state in the source; the shipped description gives the index.
    for &(state, derivative) in states {
        let named = format!("derivative=\"{}\"", variables[state].name);
        if out.matches(&named).count() != 1 {
            return Err(format!(
                "variable '{}': {named} must appear exactly once in the description",
                variables[derivative].name
            ));
        }
        out = out.replacen(&named, &format!("derivative=\"{}\"", state + 1), 1);
    }
    Ok(out)
}

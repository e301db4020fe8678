//! The parts of an FMU's modelDescription.xml the plugin needs (FMI 2.0, Co-Simulation).

use std::collections::HashMap;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Real,
    Integer,
    Boolean,
    String,
    Enumeration,
}

#[derive(Clone, Debug)]
pub struct Variable {
    pub name: String,
    pub vr: u32,
    pub kind: Kind,
    pub causality: String,
}

#[derive(Debug, Default)]
pub struct ModelDescription {
    pub model_name: String,
    pub guid: String,
    pub model_identifier: String,
    pub can_serialize: bool,
    pub variables: Vec<Variable>,
}

impl ModelDescription {
    pub fn variable(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// Reads the parts of modelDescription.xml the plugin needs (FMI 2.0, Co-Simulation).
    pub fn parse(xml: &str) -> Result<Self, String> {
        use quick_xml::events::Event;
        let mut reader = quick_xml::Reader::from_str(xml);
        let mut md = ModelDescription::default();
        let mut cs = false;
        let mut pending: Option<Variable> = None;
        loop {
            let event = reader
                .read_event()
                .map_err(|e| format!("modelDescription.xml: {e}"))?;
            let (element, empty) = match &event {
                Event::Start(e) => (e, false),
                Event::Empty(e) => (e, true),
                Event::End(e) if e.name().as_ref() == b"ScalarVariable" => {
                    if let Some(v) = pending.take() {
                        return Err(format!("variable '{}' has no type element", v.name));
                    }
                    continue;
                }
                Event::Eof => break,
                _ => continue,
            };
            let mut attributes = HashMap::new();
            for attribute in element.attributes() {
                let attribute = attribute.map_err(|e| format!("modelDescription.xml: {e}"))?;
                let value = attribute
                    .unescape_value()
                    .map_err(|e| format!("modelDescription.xml: {e}"))?;
                attributes.insert(
                    String::from_utf8_lossy(attribute.key.as_ref()).into_owned(),
                    value.into_owned(),
                );
            }
            let get = |key: &str| attributes.get(key).cloned().unwrap_or_default();
            match element.name().as_ref() {
                b"fmiModelDescription" => {
                    if get("fmiVersion") != "2.0" {
                        return Err(format!(
                            "fmiVersion is '{}': this plugin hosts FMI 2.0 FMUs",
                            get("fmiVersion")
                        ));
                    }
                    md.model_name = get("modelName");
                    md.guid = get("guid");
                }
                b"CoSimulation" => {
                    cs = true;
                    md.model_identifier = get("modelIdentifier");
                    md.can_serialize = get("canGetAndSetFMUstate") == "true"
                        && get("canSerializeFMUstate") == "true";
                }
                b"ScalarVariable" if !empty => {
                    let vr = get("valueReference").parse().map_err(|_| {
                        format!("variable '{}' has no valid valueReference", get("name"))
                    })?;
                    let causality = attributes
                        .get("causality")
                        .cloned()
                        .unwrap_or_else(|| "local".into());
                    pending = Some(Variable {
                        name: get("name"),
                        vr,
                        kind: Kind::Real,
                        causality,
                    });
                }
                name => {
                    let kind = match name {
                        b"Real" => Kind::Real,
                        b"Integer" => Kind::Integer,
                        b"Boolean" => Kind::Boolean,
                        b"String" => Kind::String,
                        b"Enumeration" => Kind::Enumeration,
                        _ => continue,
                    };
                    if let Some(mut v) = pending.take() {
                        v.kind = kind;
                        md.variables.push(v);
                    }
                }
            }
        }
        if !cs {
            return Err("the FMU does not implement Co-Simulation".into());
        }
        Ok(md)
    }
}

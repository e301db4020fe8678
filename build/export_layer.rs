// The export layer's part of every shipped model description (included by model_description.rs):
// what `src/fmi2` implements, the same for every model unless a list below names it.

/// The export layer's log categories (`src/fmi2` checks `fmi2SetDebugLogging` against them).
pub const LOG_CATEGORIES: [(&str, &str); 5] = [
    (
        "logStatusWarning",
        "Warnings: inputs outside the model's range, clamped",
    ),
    ("logStatusDiscard", "Steps that could not be completed"),
    (
        "logStatusError",
        "Errors: bad arguments, illegal call order, bad parameters",
    ),
    ("logStatusFatal", "Fatal errors: internal faults"),
    ("logCalls", "Every FMI function call (debug logging)"),
];

/// The capabilities of the export layer in `src/fmi2`, the same for every model.
const CO_SIMULATION_CAPABILITIES: &str = r#"needsExecutionTool="false"
    canHandleVariableCommunicationStepSize="true"
    canInterpolateInputs="false"
    maxOutputDerivativeOrder="0"
    canRunAsynchronuously="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canNotUseMemoryManagementFunctions="true"
    canGetAndSetFMUstate="true"
    canSerializeFMUstate="true""#;

/// The Model Exchange capabilities of the export layer (`src/export/instance/model_exchange.rs`): the friction
/// history is committed at completed integrator steps, so the importer must call them.
const MODEL_EXCHANGE_CAPABILITIES: &str = r#"needsExecutionTool="false"
    completedIntegratorStepNotNeeded="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canNotUseMemoryManagementFunctions="true"
    canGetAndSetFMUstate="true"
    canSerializeFMUstate="true""#;

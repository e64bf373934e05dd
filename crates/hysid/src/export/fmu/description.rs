//! The FMU's XML files: `modelDescription.xml` (FMI 2.0, `fmi2ModelDescription.xsd`) and
//! `sources/buildDescription.xml` (the build description of source-code FMUs, whose format
//! FMI 2.0.4 adopted from FMI 3.0: `fmi3BuildDescription.xsd`, `fmiVersion="3.0"`).
//!
//! Variables, all `Real`, in value-reference order:
//!
//! | value references | variables | causality, variability, initial |
//! |---|---|---|
//! | 0 … n_in − 1 | the inputs, named after [`Interface::inputs`] | `input`, `discrete`, start 0 |
//! | n_in … n_in + n_out − 1 | the outputs ([`Interface::outputs`]) | `output`, `discrete`, `calculated` |
//! | then | the model's parameters ([`Interface::parameters`]) | `calculatedParameter`, `fixed`, `calculated` |
//!
//! The variables are `discrete`: a sampled model's inputs and outputs change at
//! communication points only. The parameters are the values the code was generated with,
//! fixed in it: FMI's `calculatedParameter` (read with `fmi2GetReal`, never set), not
//! `parameter`, which a host could set and expect the model to follow. Every output is
//! declared to depend on every input (the attribute `dependencies` left out): whether an
//! output feeds an input through depends on the model, and the superset is always right.

use super::super::Interface;
use crate::{Error, Result};

/// The source files of the FMU (in `sources/`) that are compiled, in compile order.
pub fn compiled_sources(name: &str) -> [String; 2] {
    [format!("{name}.c"), format!("fmu_{name}.c")]
}

/// `modelDescription.xml` of the FMU of `interface`, with `guid`.
pub fn model_description(interface: &Interface, guid: &str) -> Result<String> {
    check_names(interface)?;
    let name = &interface.name;
    let mut xml = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    xml += &format!(
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{name}\" guid=\"{guid}\" \
         description=\"{}\" generationTool=\"hysid {}\" variableNamingConvention=\"flat\" \
         numberOfEventIndicators=\"0\">\n",
        escape(&interface.description),
        env!("CARGO_PKG_VERSION"),
    );
    xml += &format!(
        "  <CoSimulation modelIdentifier=\"{name}\" needsExecutionTool=\"false\" \
         canHandleVariableCommunicationStepSize=\"false\" canInterpolateInputs=\"false\" \
         maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\" \
         canBeInstantiatedOnlyOncePerProcess=\"false\" \
         canNotUseMemoryManagementFunctions=\"false\" canGetAndSetFMUstate=\"true\" \
         canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\">\n    \
         <SourceFiles>\n"
    );
    for file in compiled_sources(name) {
        xml += &format!("      <File name=\"{file}\"/>\n");
    }
    xml += "    </SourceFiles>\n  </CoSimulation>\n";
    xml += "  <LogCategories>\n    <Category name=\"logStatusError\" \
            description=\"a call refused with fmi2Error, and why\"/>\n  </LogCategories>\n";
    if interface.sample_time > 0.0 {
        xml += &format!(
            "  <DefaultExperiment startTime=\"0.0\" stepSize=\"{}\"/>\n",
            real(interface.sample_time)
        );
    }
    xml += "  <ModelVariables>\n";
    let mut reference = 0usize;
    for (k, input) in interface.inputs.iter().enumerate() {
        xml += &variable(
            input,
            reference,
            &format!("input {} of {name}_step", k + 1),
            "causality=\"input\" variability=\"discrete\"",
            "<Real start=\"0.0\"/>",
        );
        reference += 1;
    }
    for (k, output) in interface.outputs.iter().enumerate() {
        xml += &variable(
            output,
            reference,
            &format!("output {} of {name}_step", k + 1),
            "causality=\"output\" variability=\"discrete\" initial=\"calculated\"",
            "<Real/>",
        );
        reference += 1;
    }
    for (parameter, value) in &interface.parameters {
        xml += &variable(
            parameter,
            reference,
            &format!("{parameter} = {}, fixed in the code", real(*value)),
            "causality=\"calculatedParameter\" variability=\"fixed\" initial=\"calculated\"",
            "<Real/>",
        );
        reference += 1;
    }
    xml += "  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n";
    // Indices into ModelVariables are one-based.
    let first_output = interface.inputs.len() + 1;
    let outputs = first_output..first_output + interface.outputs.len();
    for index in outputs.clone() {
        xml += &format!("      <Unknown index=\"{index}\"/>\n");
    }
    xml += "    </Outputs>\n    <InitialUnknowns>\n";
    for index in outputs.clone() {
        xml += &format!("      <Unknown index=\"{index}\"/>\n");
    }
    for index in outputs.end..outputs.end + interface.parameters.len() {
        xml += &format!("      <Unknown index=\"{index}\" dependencies=\"\"/>\n");
    }
    xml += "    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n";
    Ok(xml)
}

/// `sources/buildDescription.xml`: the two C files of [`compiled_sources`], C99, linked
/// with the C math library.
pub fn build_description(name: &str) -> String {
    let mut xml = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiBuildDescription fmiVersion=\"3.0\">\n",
    );
    xml += &format!(
        "  <BuildConfiguration modelIdentifier=\"{name}\" description=\"the model and its FMI \
         2.0 Co-Simulation interface\">\n    <SourceFileSet language=\"C99\">\n"
    );
    for file in compiled_sources(name) {
        xml += &format!("      <SourceFile name=\"{file}\"/>\n");
    }
    xml += "    </SourceFileSet>\n    <Library name=\"m\" external=\"true\" \
            description=\"the C math library (-lm)\"/>\n  </BuildConfiguration>\n\
            </fmiBuildDescription>\n";
    xml
}

/// One `ScalarVariable` element.
fn variable(
    name: &str,
    reference: usize,
    description: &str,
    attributes: &str,
    real: &str,
) -> String {
    format!(
        "    <ScalarVariable name=\"{}\" valueReference=\"{reference}\" description=\"{}\" \
         {attributes}>\n      {real}\n    </ScalarVariable>\n",
        escape(name),
        escape(description)
    )
}

/// A number as XML Schema's `xs:double` reads it back to the same value (Rust's shortest
/// round-trip form: `0.001`, `1e-7`, `2.0`).
pub fn real(value: f64) -> String {
    format!("{value:?}")
}

/// Refuses what the model description cannot hold: names that are not one per input and
/// output, empty or with control characters, a name used twice, a non-finite parameter.
fn check_names(interface: &Interface) -> Result<()> {
    let bad = |message: String| {
        Err(Error::InvalidModel(format!(
            "FMU of {}: {message}",
            interface.name
        )))
    };
    if interface.inputs.len() != interface.n_inputs
        || interface.outputs.len() != interface.n_outputs
        || interface.n_inputs == 0
        || interface.n_outputs == 0
    {
        return bad(format!(
            "{} input and {} output names for {} inputs and {} outputs (at least one of each)",
            interface.inputs.len(),
            interface.outputs.len(),
            interface.n_inputs,
            interface.n_outputs
        ));
    }
    if !(interface.sample_time >= 0.0 && interface.sample_time.is_finite()) {
        return bad(format!(
            "the sample time {} is not a finite number ≥ 0",
            interface.sample_time
        ));
    }
    let names: Vec<&str> = interface
        .inputs
        .iter()
        .chain(&interface.outputs)
        .map(String::as_str)
        .chain(interface.parameters.iter().map(|(n, _)| n.as_str()))
        .collect();
    for (k, name) in names.iter().enumerate() {
        if name.trim().is_empty() || name.chars().any(char::is_control) {
            return bad(format!(
                "the variable name '{name}' is empty or holds control characters; rename the \
                 data column"
            ));
        }
        if names[..k].contains(name) {
            return bad(format!(
                "two variables are named '{name}' (inputs, outputs and parameters share one \
                 namespace); rename the data column"
            ));
        }
    }
    if let Some((name, value)) = interface.parameters.iter().find(|(_, v)| !v.is_finite()) {
        return bad(format!("parameter {name} = {value} is not finite"));
    }
    Ok(())
}

/// `text` with the five XML special characters escaped, for an attribute value.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Attribute values normalise whitespace; keep a line break a line break.
            '\n' => out.push_str("&#10;"),
            '\t' => out.push_str("&#9;"),
            '\r' => out.push_str("&#13;"),
            // Other control characters cannot appear in XML 1.0 at all.
            c if c.is_control() => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

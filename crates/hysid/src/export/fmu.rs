//! The FMU target: the C code of a model ([`CCode`]) as an FMI 2.0 Co-Simulation FMU.
//!
//! `NAME.fmu` is a ZIP archive ([`super::zip`]) holding
//!
//! | entry | what |
//! |---|---|
//! | `modelDescription.xml` | the interface: inputs, outputs, parameters ([`description`]) |
//! | `documentation/index.html` | what the FMU is and how it steps |
//! | `documentation/licenses/fmi2-headers-LICENSE.txt` | the BSD 2-Clause license of the FMI headers |
//! | `sources/buildDescription.xml` | how to build the binary from the sources |
//! | `sources/NAME.h`, `sources/NAME.c` | the model, exactly as the C target writes it |
//! | `sources/fmu_NAME.c` | the FMI 2.0 Co-Simulation functions around `NAME_step` |
//! | `sources/fmi2*.h` | the FMI 2.0 headers ([`FMI2_HEADERS`], vendored in `export/fmi2/`) |
//! | `binaries/linux64/NAME.so` | unless [`ExportOptions::binary`] is off ([`Compiler`]) |
//!
//! **Stepping.** The wrapper (`export/fmu/wrapper.c`, documented at its top) keeps one
//! `NAME_state` per instance, allocated with the host's `allocateMemory`. At a communication
//! point the outputs are what `NAME_step` returns for the current state and the inputs as
//! set — the sample `hysid simulate` reports there — and `fmi2DoStep` advances the state by
//! one `NAME_step` per sample time, the inputs held. The communication step must be a whole
//! multiple of the model's sample time (`DefaultExperiment stepSize`); anything else is
//! refused with `fmi2Error` and a logged message. A host that records the outputs after
//! `fmi2DoStep` and sets the next inputs only afterwards (fmpy's `simulate_fmu` does) sees,
//! for a model whose output depends directly on its input, that output with the previous
//! input held; asked again after setting the inputs, the FMU answers the model's sample.
//!
//! **Capabilities.** Variable communication step sizes, input interpolation, output
//! derivatives, directional derivatives and asynchronous steps are declared absent and their
//! functions return `fmi2Error`; `fmi2Reset` restarts from the model's initial state; FMU
//! states can be got, set and serialised (the state's bytes, read back by the same binary).
//!
//! **Reproducible.** The GUID is a hash of the sources and the model description, the ZIP
//! entries carry one fixed timestamp, and the binary is built from relative paths: the same
//! export gives the same bytes (with the same compiler).

mod compile;
pub mod description;

pub use crate::toolchain::Compiler;

use super::zip::{archive, Entry};
use super::{check_name, CCode, ExportOptions, GeneratedFile};
use crate::Result;

/// The FMI 2.0 headers the wrapper is compiled against, shipped in `sources/`: file name
/// and text (BSD 2-Clause, see `export/fmi2/README.md`).
pub const FMI2_HEADERS: [(&str, &str); 3] = [
    (
        "fmi2TypesPlatform.h",
        include_str!("fmi2/fmi2TypesPlatform.h"),
    ),
    (
        "fmi2FunctionTypes.h",
        include_str!("fmi2/fmi2FunctionTypes.h"),
    ),
    ("fmi2Functions.h", include_str!("fmi2/fmi2Functions.h")),
];

/// The license of [`FMI2_HEADERS`], shipped as
/// `documentation/licenses/fmi2-headers-LICENSE.txt`.
pub const FMI2_LICENSE: &str = include_str!("fmi2/LICENSE.txt");

/// The template of `sources/fmu_NAME.c`.
const WRAPPER: &str = include_str!("fmu/wrapper.c");

/// The FMU of `code`: one file, `NAME.fmu`, with a binary built by the machine's C compiler
/// ([`Compiler::from_env`]) unless `options.binary` is off.
pub fn fmu_files(code: &CCode, options: &ExportOptions) -> Result<Vec<GeneratedFile>> {
    let compiler = options.binary.then(Compiler::from_env);
    Ok(vec![GeneratedFile {
        path: format!("{}.fmu", code.interface.name).into(),
        contents: fmu(code, compiler.as_ref())?,
    }])
}

/// The bytes of the FMU of `code`, its binary built by `compiler` (none: a source-only FMU).
pub fn fmu(code: &CCode, compiler: Option<&Compiler>) -> Result<Vec<u8>> {
    let interface = &code.interface;
    let name = &interface.name;
    check_name(name)?;
    let unhashed = description::model_description(interface, "")?;
    let guid = guid(&[
        code.header.as_bytes(),
        code.source.as_bytes(),
        unhashed.as_bytes(),
    ]);
    let mut sources: Vec<(String, Vec<u8>)> = vec![
        (format!("{name}.h"), code.header.clone().into_bytes()),
        (format!("{name}.c"), code.source.clone().into_bytes()),
        (format!("fmu_{name}.c"), wrapper(code, &guid).into_bytes()),
    ];
    sources.extend(
        FMI2_HEADERS
            .iter()
            .map(|(file, text)| (file.to_string(), text.as_bytes().to_vec())),
    );
    let binary = match compiler {
        Some(cc) => Some(compile::shared_library(
            cc,
            name,
            &sources,
            &description::compiled_sources(name),
        )?),
        None => None,
    };
    let mut entries = vec![
        Entry::new(
            "modelDescription.xml",
            description::model_description(interface, &guid)?,
        ),
        Entry::new("documentation/index.html", documentation(code)),
        Entry::new(
            "documentation/licenses/fmi2-headers-LICENSE.txt",
            FMI2_LICENSE,
        ),
        Entry::new(
            "sources/buildDescription.xml",
            description::build_description(name),
        ),
    ];
    entries.extend(
        sources
            .into_iter()
            .map(|(file, data)| Entry::new(format!("sources/{file}"), data)),
    );
    entries.extend(binary.map(|(path, data)| Entry::new(path, data)));
    archive(&entries)
}

/// `sources/fmu_NAME.c`: the template filled in.
fn wrapper(code: &CCode, guid: &str) -> String {
    let parameters = &code.interface.parameters;
    let values = if parameters.is_empty() {
        // A one-element array: C has no empty initialiser.
        "0.0".to_string()
    } else {
        parameters
            .iter()
            .map(|(_, v)| description::real(*v))
            .collect::<Vec<_>>()
            .join(", ")
    };
    WRAPPER
        .replace("@NAME@", &code.interface.name)
        .replace("@VERSION@", env!("CARGO_PKG_VERSION"))
        .replace("@GUID@", guid)
        .replace("@N_PAR@", &parameters.len().to_string())
        .replace("@PARAMETERS@", &values)
}

/// `documentation/index.html`.
fn documentation(code: &CCode) -> String {
    let i = &code.interface;
    let list = |names: &[String]| escape_html(&names.join(", "));
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head><meta charset=\"utf-8\"><title>{name}</title></head>\n\
         <body>\n<h1>{name}</h1>\n<p>{description}</p>\n\
         <p>An FMI 2.0 Co-Simulation FMU generated by hysid {version}. Inputs: {inputs}. \
         Outputs: {outputs}. Sample time: {ts} s.</p>\n\
         <p>At a communication point the outputs are the model's sample for the current state \
         and the inputs as set; <code>fmi2DoStep</code> advances the model by one sample per \
         sample time in the step, the inputs held. The step must be a whole multiple of the \
         sample time. The parameters are fixed in the code (calculated parameters, read-only).</p>\n\
         <p>The sources are in <code>sources/</code> (<code>{name}.c</code> and \
         <code>fmu_{name}.c</code>, C99, linked with <code>-lm</code>). The FMI 2.0 headers are \
         under the BSD 2-Clause license in <code>licenses/fmi2-headers-LICENSE.txt</code>.</p>\n\
         </body>\n</html>\n",
        name = i.name,
        description = escape_html(&i.description),
        version = env!("CARGO_PKG_VERSION"),
        inputs = list(&i.inputs),
        outputs = list(&i.outputs),
        ts = description::real(i.sample_time),
    )
}

fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A GUID derived from `parts`: the first 128 bits of their BLAKE3 hash (each part
/// followed by its length, so that moving bytes between parts changes it), written as
/// `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}`.
pub fn guid(parts: &[&[u8]]) -> String {
    let mut hasher = blake3::Hasher::new();
    for part in parts {
        hasher.update(part);
        hasher.update(&(part.len() as u64).to_le_bytes());
    }
    let hex = hasher.finalize().to_hex();
    let hex = &hex[..32];
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &hex[..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..]
    )
}

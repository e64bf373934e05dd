//! `export::fmu` on a hand-written model that follows the C contract: a first-order filter
//! with direct feedthrough, `y_k = x_k + d u_k`, `x_{k+1} = a x_k + (1 − a) u_k`. The FMU's
//! files, its reproducibility, the refusals, and the wrapper compiled with the strict flags
//! and driven through the FMI functions by a small C host.

use super::zip::read_zip;
use hysid::error::Category;
use hysid::export::fmu::{fmu, fmu_files, Compiler};
use hysid::export::{CCode, ExportOptions, Interface};
use std::path::Path;
use std::process::Command;

const A: f64 = 0.9;
const D: f64 = 0.5;
const TS: f64 = 0.01;

/// The filter as the C target would write it, under the export name `name`.
fn filter(name: &str) -> CCode {
    let header = format!(
        "#ifndef {name}_h\n#define {name}_h\n#include <stddef.h>\n\
         #define {name}_N_INPUTS 1\n#define {name}_N_OUTPUTS 1\n#define {name}_SAMPLE_TIME {TS:?}\n\
         typedef struct {{ double x; }} {name}_state;\n\
         void {name}_init({name}_state *s);\n\
         void {name}_step({name}_state *s, const double *u, double *y);\n#endif\n"
    );
    let source = format!(
        "#include <math.h>\n#include <stddef.h>\n#include \"{name}.h\"\n\
         void {name}_init({name}_state *s) {{ s->x = 0.0; }}\n\
         void {name}_step({name}_state *s, const double *u, double *y)\n\
         {{\n    y[0] = s->x + {D:?} * u[0];\n    s->x = {A:?} * s->x + (1.0 - {A:?}) * u[0];\n}}\n"
    );
    CCode {
        header,
        source,
        interface: Interface {
            name: name.into(),
            n_inputs: 1,
            n_outputs: 1,
            sample_time: TS,
            inputs: vec!["u & v".into()],
            outputs: vec!["y".into()],
            parameters: vec![("a".into(), A), ("d".into(), D)],
            description: "a first-order filter written by hand".into(),
        },
    }
}

fn names(bytes: &[u8]) -> Vec<String> {
    read_zip(bytes).into_iter().map(|(n, _, _)| n).collect()
}

fn entry(bytes: &[u8], name: &str) -> Vec<u8> {
    read_zip(bytes)
        .into_iter()
        .find(|(n, _, _)| n == name)
        .unwrap_or_else(|| panic!("no {name}"))
        .2
}

const SOURCES: [&str; 10] = [
    "modelDescription.xml",
    "documentation/index.html",
    "documentation/licenses/fmi2-headers-LICENSE.txt",
    "sources/buildDescription.xml",
    "sources/lp.h",
    "sources/lp.c",
    "sources/fmu_lp.c",
    "sources/fmi2TypesPlatform.h",
    "sources/fmi2FunctionTypes.h",
    "sources/fmi2Functions.h",
];

#[test]
fn a_source_only_fmu_holds_the_sources_and_the_license() {
    let options = ExportOptions {
        binary: false,
        ..ExportOptions::default()
    };
    let files = fmu_files(&filter("lp"), &options).unwrap();
    assert_eq!(files.len(), 1);
    assert_eq!(files[0].path, Path::new("lp.fmu"));
    assert_eq!(names(&files[0].contents), SOURCES);
    let code = filter("lp");
    assert_eq!(
        entry(&files[0].contents, "sources/lp.c"),
        code.source.as_bytes()
    );
    let license = String::from_utf8(entry(
        &files[0].contents,
        "documentation/licenses/fmi2-headers-LICENSE.txt",
    ))
    .unwrap();
    assert!(license.contains("BSD 2-Clause"));
}

#[test]
fn the_model_description_names_the_variables_and_the_guid_ties_it_to_the_code() {
    let bytes = fmu(&filter("lp"), None).unwrap();
    let xml = String::from_utf8(entry(&bytes, "modelDescription.xml")).unwrap();
    for expected in [
        "fmiVersion=\"2.0\"",
        "modelIdentifier=\"lp\"",
        "name=\"u &amp; v\" valueReference=\"0\"",
        "causality=\"input\"",
        "name=\"y\" valueReference=\"1\"",
        "name=\"a\" valueReference=\"2\"",
        "name=\"d\" valueReference=\"3\"",
        "causality=\"calculatedParameter\"",
        "stepSize=\"0.01\"",
        "<File name=\"fmu_lp.c\"/>",
        "<Unknown index=\"2\"/>",
    ] {
        assert!(xml.contains(expected), "{expected} missing:\n{xml}");
    }
    let guid = xml
        .split("guid=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    assert_eq!(guid.len(), 38, "{guid}");
    let wrapper = String::from_utf8(entry(&bytes, "sources/fmu_lp.c")).unwrap();
    assert!(wrapper.contains(&format!("#define GUID \"{guid}\"")));
    // Another model, another GUID.
    let mut other = filter("lp");
    other.interface.parameters[0].1 = 0.8;
    other.source = other.source.replace("0.9", "0.8");
    let other = fmu(&other, None).unwrap();
    assert!(!String::from_utf8(entry(&other, "modelDescription.xml"))
        .unwrap()
        .contains(guid));
}

#[test]
fn clashing_names_and_inconsistent_interfaces_are_refused() {
    let mut code = filter("lp");
    code.interface.outputs = vec!["a".into()];
    let err = fmu(&code, None).unwrap_err();
    assert!(
        err.to_string().contains("two variables are named 'a'"),
        "{err}"
    );
    let mut code = filter("lp");
    code.interface.inputs.push("w".into());
    let err = fmu(&code, None).unwrap_err().to_string();
    assert!(err.contains("2 input and 1 output names"), "{err}");
    let mut code = filter("lp");
    code.interface.name = "int".into();
    assert!(fmu(&code, None).is_err());
}

#[test]
fn the_binary_is_built_and_the_export_is_byte_identical() {
    let cc = Compiler::new("cc");
    let first = fmu(&filter("lp"), Some(&cc)).unwrap();
    let mut expected: Vec<String> = SOURCES.iter().map(|s| s.to_string()).collect();
    expected.push("binaries/linux64/lp.so".into());
    assert_eq!(names(&first), expected);
    assert_eq!(fmu(&filter("lp"), Some(&cc)).unwrap(), first);
}

/// A compiler given with arguments (`CC="env cc"`, as `CC="ccache cc"` would be) builds
/// the same binary.
#[test]
fn a_compiler_with_arguments_builds_the_binary() {
    let env_cc = Compiler::parse(std::ffi::OsStr::new("env cc"));
    let first = fmu(&filter("lp"), Some(&env_cc)).unwrap();
    assert!(names(&first).contains(&"binaries/linux64/lp.so".to_string()));
    assert_eq!(
        first,
        fmu(&filter("lp"), Some(&Compiler::new("cc"))).unwrap()
    );
}

#[test]
fn no_compiler_is_one_line_naming_it_and_the_way_out() {
    let err = fmu(&filter("lp"), Some(&Compiler::new("/nonexistent/cc"))).unwrap_err();
    let text = err.to_string();
    assert_eq!(err.category(), Category::Config);
    assert_eq!(text.lines().count(), 1);
    assert!(
        text.contains("no C compiler")
            && text.contains("/nonexistent/cc")
            && text.contains("--no-binary"),
        "{text}"
    );
}

/// A host written against the FMI functions: feeds u_k = k + 1, prints the output at each
/// communication point, then exercises the refusals, a double step and fmi2Reset.
const HOST: &str = r#"
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include "fmi2Functions.h"
static void logger(fmi2ComponentEnvironment e, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list ap;
    (void)e; (void)instance; (void)category;
    va_start(ap, message);
    printf("log %d: ", (int)status);
    vprintf(message, ap);
    printf("\n");
    va_end(ap);
}
int main(int argc, char **argv)
{
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2ValueReference u = 0, y = 1, d = 3;
    double v, t = 0.0;
    int k;
    fmi2Component c;
    (void)argc;
    if (fmi2Instantiate("bad", fmi2CoSimulation, "{not-it}", "", &cb, 0, 0) != NULL) return 2;
    c = fmi2Instantiate("host", fmi2CoSimulation, argv[1], "", &cb, 0, 0);
    if (c == NULL) return 1;
    fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0);
    fmi2EnterInitializationMode(c);
    fmi2ExitInitializationMode(c);
    for (k = 0; k < 5; k++) {
        v = k + 1.0;
        fmi2SetReal(c, &u, 1, &v);
        fmi2GetReal(c, &y, 1, &v);
        printf("y %.17g\n", v);
        if (fmi2DoStep(c, t, 0.01, 1) != fmi2OK) return 3;
        t += 0.01;
    }
    fmi2GetReal(c, &d, 1, &v);
    printf("d %.17g\n", v);
    printf("status %d\n", (int)fmi2DoStep(c, t, 0.015, 1));
    printf("status %d\n", (int)fmi2SetReal(c, &d, 1, &v));
    printf("status %d\n", (int)fmi2DoStep(c, t, 0.02, 1));
    fmi2GetReal(c, &y, 1, &v);
    printf("y %.17g\n", v);
    fmi2Reset(c);
    fmi2EnterInitializationMode(c);
    fmi2ExitInitializationMode(c);
    v = 1.0;
    fmi2SetReal(c, &u, 1, &v);
    fmi2GetReal(c, &y, 1, &v);
    printf("y %.17g\n", v);
    fmi2FreeInstance(c);
    return 0;
}
"#;

#[test]
fn the_wrapper_compiles_strictly_and_steps_as_the_model() {
    let dir = tempfile::TempDir::new().unwrap();
    let bytes = fmu(&filter("lp"), None).unwrap();
    for (name, _, data) in read_zip(&bytes) {
        if let Some(file) = name.strip_prefix("sources/") {
            std::fs::write(dir.path().join(file), data).unwrap();
        }
    }
    std::fs::write(dir.path().join("host.c"), HOST).unwrap();
    let xml = String::from_utf8(entry(&bytes, "modelDescription.xml")).unwrap();
    let guid = xml
        .split("guid=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    let build = Command::new("cc")
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-O2",
        ])
        .args(["-o", "host", "host.c", "lp.c", "fmu_lp.c", "-lm"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    let run = Command::new(dir.path().join("host"))
        .arg(guid)
        .output()
        .unwrap();
    let out = String::from_utf8(run.stdout).unwrap();
    assert!(run.status.success(), "{out}");
    // The model in Rust, the same operations in the same order.
    let (mut x, mut expected) = (0.0f64, String::new());
    for k in 0..5 {
        let u = k as f64 + 1.0;
        expected += &format!("y {}\n", x + D * u);
        x = A * x + (1.0 - A) * u;
    }
    let mut lines = out.lines();
    assert!(lines.next().unwrap().contains("GUID given is not"), "{out}");
    let got: String = lines.by_ref().take(5).map(|l| format!("{l}\n")).collect();
    let parse =
        |text: &str| -> Vec<f64> { text.lines().map(|l| l[2..].parse().unwrap()).collect() };
    for (g, e) in parse(&got).iter().zip(parse(&expected)) {
        assert!((g - e).abs() <= 1e-15 * e.abs(), "{got} vs {expected}");
    }
    let rest: Vec<&str> = lines.collect();
    assert_eq!(rest[0], "d 0.5");
    assert!(rest[1].contains("not a whole multiple"), "{rest:?}");
    assert_eq!(rest[2], "status 3"); // fmi2Error
    assert!(rest[3].contains("only the inputs can be set"), "{rest:?}");
    assert_eq!(rest[4], "status 3");
    assert_eq!(rest[5], "status 0"); // two samples in one step
                                     // Two more steps with u = 5 held, then the output with u = 5.
    let (mut x2, u) = (x, 5.0);
    for _ in 0..2 {
        x2 = A * x2 + (1.0 - A) * u;
    }
    let y: f64 = rest[6][2..].parse().unwrap();
    assert!((y - (x2 + D * u)).abs() < 1e-14, "{y}");
    // After fmi2Reset the state is the initial one again.
    assert_eq!(rest[7], format!("y {}", D));
}

//! Inputs are sacred: every output flag of every command, pointed at every file the command
//! reads — directly, as `sub/../file`, through a symbolic link, through a hard link, and for
//! an input directory at each file read from inside it — is a usage error (exit 2) of one
//! line naming both flags, given before any work, and the input stays byte for byte as it
//! was. So are two outputs on one file and a file output inside the directory output.

use crate::common::hysid;
use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

/// One command: its arguments without outputs, its inputs (flag, name in the work
/// directory) and its outputs (flag, whether a directory).
struct Command {
    args: Vec<&'static str>,
    inputs: Vec<(&'static str, &'static str)>,
    outputs: Vec<(&'static str, bool)>,
    /// An output the command requires (given a fresh path when another is tested).
    required: Option<&'static str>,
}

/// Every command that reads a file, with the inputs and outputs it has.
fn commands() -> Vec<Command> {
    let (file, dir) = (false, true);
    let models = [("--json", file), ("--model-out", file), ("--plots", dir)];
    vec![
        Command {
            args: vec![
                "identify",
                "cascade",
                "--input",
                "x",
                "--output",
                "y",
                "--hysteresis",
                "ch4",
                "--na",
                "2",
                "--nb",
                "2",
                "--delay",
                "1",
            ],
            inputs: vec![("--data", "data.csv")],
            outputs: models.to_vec(),
            required: None,
        },
        Command {
            args: vec![
                "identify",
                "hysteresis",
                "--input",
                "x",
                "--output",
                "y",
                "--hysteresis",
                "ch4",
            ],
            inputs: vec![("--data", "data.csv")],
            outputs: models.to_vec(),
            required: None,
        },
        Command {
            args: vec![
                "identify", "operator", "--family", "pi", "--input", "x", "--output", "y",
            ],
            inputs: vec![("--data", "data.csv")],
            outputs: models.to_vec(),
            required: None,
        },
        Command {
            args: vec!["simulate", "--input", "x", "--output", "y"],
            inputs: vec![("--model", "model.json"), ("--data", "data.csv")],
            outputs: vec![("--json", file), ("--csv", file)],
            required: None,
        },
        Command {
            args: vec!["greybox", "fit", "--input", "u_N", "--output", "y_m"],
            inputs: vec![("--model-file", "model.toml"), ("--data", "data.csv")],
            outputs: models.to_vec(),
            required: None,
        },
        Command {
            args: vec!["benchmark", "bouc-wen", "--starts", "1"],
            inputs: vec![("--train", "data.csv"), ("--test", "test.csv")],
            outputs: models.to_vec(),
            required: None,
        },
        Command {
            args: vec!["actuator", "identify"],
            inputs: vec![("--data", "rig")],
            outputs: models.to_vec(),
            required: None,
        },
        Command {
            args: vec!["rigid-body", "ls", "--position", "q", "--input", "u"],
            inputs: vec![("--data", "data.csv"), ("--validate", "test.csv")],
            outputs: vec![("--json", file), ("--model-out", file)],
            required: None,
        },
        Command {
            args: vec!["compare", "--input", "x", "--output", "y"],
            inputs: vec![("--data", "data.csv"), ("--validate", "test.csv")],
            outputs: models.to_vec(),
            required: None,
        },
        Command {
            args: vec!["compensate", "--reference", "x"],
            inputs: vec![("--model", "model.json"), ("--data", "data.csv")],
            outputs: vec![("--csv", file), ("--json", file), ("--plots", dir)],
            required: Some("--csv"),
        },
    ]
}

/// The inputs every command may read, in a fresh directory: two records, a model file, an
/// equation file (parsed before the outputs are registered, so a real one) and a rig
/// directory. The contents do not matter otherwise: a clash is refused before any is read.
fn work_dir() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let record = "t,x,y,u,q,u_N,y_m,t_s\n0,0,0,0,0,0,0,0\n1,1,2,1,2,1,2,1\n2,0,1,0,1,0,1,2\n";
    fs::write(dir.join("data.csv"), record).unwrap();
    fs::write(dir.join("test.csv"), record.replace(",1,", ",3,")).unwrap();
    fs::write(dir.join("model.json"), r#"{"kind": "ch_cascade"}"#).unwrap();
    let equations =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/equations/bouc_wen.toml");
    fs::copy(equations, dir.join("model.toml")).unwrap();
    fs::create_dir(dir.join("rig")).unwrap();
    for k in 1..=8 {
        fs::write(
            dir.join(format!("rig/dataset{k}.csv")),
            "t_s,tau_Nm,theta_rad\n0,0,0\n",
        )
        .unwrap();
    }
    fs::write(dir.join("rig/rig.json"), "{}").unwrap();
    fs::create_dir(dir.join("sub")).unwrap();
    tmp
}

/// Every file under `dir` (links as the bytes they lead to) by relative path.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let meta = fs::symlink_metadata(&path).unwrap();
            if meta.is_dir() {
                pending.push(path);
            } else {
                let bytes = fs::read(&path).unwrap_or_default();
                files.insert(path.strip_prefix(dir).unwrap().to_path_buf(), bytes);
            }
        }
    }
    files
}

/// How an output names an input: (label, the output's value, links to make first as
/// (link, target, hard)).
type Spelling = (String, String, Vec<(String, String, bool)>);

/// The spellings of `input` (a file, or the directory `rig`) as the value of an output flag.
fn spellings(input: &str, output_is_dir: bool) -> Vec<Spelling> {
    let mut all: Vec<Spelling> = vec![
        ("directly".into(), input.into(), vec![]),
        ("as sub/..".into(), format!("sub/../{input}"), vec![]),
        (
            "through a symbolic link".into(),
            "link".into(),
            vec![("link".into(), input.into(), false)],
        ),
    ];
    if input == "rig" {
        for inside in ["dataset1.csv", "rig.json"] {
            all.push((inside.into(), format!("rig/{inside}"), vec![]));
            all.push((
                format!("{inside} as ../"),
                format!("rig/../rig/{inside}"),
                vec![],
            ));
        }
        all.push((
            "a hard link of a file inside".into(),
            "hard".into(),
            vec![("hard".into(), "rig/dataset2.csv".into(), true)],
        ));
        all.push((
            "a symbolic link to a file inside".into(),
            "link".into(),
            vec![("link".into(), "rig/rig.json".into(), false)],
        ));
    } else {
        all.push((
            "through a hard link".into(),
            "hard".into(),
            vec![("hard".into(), input.into(), true)],
        ));
    }
    if output_is_dir {
        all.push(("the directory holding it".into(), ".".into(), vec![]));
    }
    all
}

/// Runs `args` in `dir`; expects exit 2 with one line on stderr naming `flags`, nothing on
/// stdout (refused before any work) and every file of `dir` unchanged.
fn refused(dir: &Path, args: &[String], flags: &[&str], what: &str) {
    let before = snapshot(dir);
    let out = hysid().current_dir(dir).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let context = format!("{what}: hysid {}\nstderr: {stderr}", args.join(" "));
    assert_eq!(out.status.code(), Some(2), "{context}");
    assert_eq!(stderr.lines().count(), 1, "{context}");
    assert!(stderr.starts_with("error: "), "{context}");
    for flag in flags {
        assert!(stderr.contains(&format!("{flag} ")), "no {flag}: {context}");
    }
    assert!(out.stdout.is_empty(), "work was done: {context}");
    assert!(before == snapshot(dir), "a file changed: {context}");
}

#[test]
fn no_output_flag_of_any_command_can_replace_an_input() {
    let mut runs = 0;
    for command in commands() {
        for &(output, is_dir) in &command.outputs {
            for &(input_flag, input) in &command.inputs {
                for (label, value, links) in spellings(input, is_dir) {
                    let tmp = work_dir();
                    let dir = tmp.path();
                    for (link, target, hard) in &links {
                        if *hard {
                            fs::hard_link(dir.join(target), dir.join(link)).unwrap();
                        } else {
                            std::os::unix::fs::symlink(target, dir.join(link)).unwrap();
                        }
                    }
                    let mut args: Vec<String> =
                        command.args.iter().map(|a| a.to_string()).collect();
                    for &(flag, name) in &command.inputs {
                        args.extend([flag.to_string(), name.to_string()]);
                    }
                    args.extend([output.to_string(), value]);
                    if let Some(flag) = command.required.filter(|f| *f != output) {
                        args.extend([flag.to_string(), "fresh.csv".into()]);
                    }
                    let what = format!("{output} = {input_flag} {input} {label}");
                    // The directory holding every input names the first it finds.
                    let flags: &[&str] = if label.starts_with("the directory") {
                        &[output]
                    } else {
                        &[output, input_flag]
                    };
                    refused(dir, &args, flags, &what);
                    runs += 1;
                }
            }
        }
    }
    assert!(runs > 200, "{runs} runs");
}

#[test]
fn two_outputs_of_one_file_or_one_inside_the_other_are_refused() {
    for command in commands() {
        let files: Vec<&str> = command
            .outputs
            .iter()
            .filter(|(_, d)| !d)
            .map(|(f, _)| *f)
            .collect();
        let dirs: Vec<&str> = command
            .outputs
            .iter()
            .filter(|(_, d)| *d)
            .map(|(f, _)| *f)
            .collect();
        let base = || {
            let mut args: Vec<String> = command.args.iter().map(|a| a.to_string()).collect();
            for &(flag, name) in &command.inputs {
                args.extend([flag.to_string(), name.to_string()]);
            }
            args
        };
        // compensate's --csv is required: these runs give it as one of the pair.
        let files: Vec<&str> = match command.required {
            Some(flag) if !files.is_empty() => {
                let mut rest: Vec<&str> = files.iter().copied().filter(|f| *f != flag).collect();
                rest.insert(0, flag);
                rest
            }
            _ => files,
        };
        let tmp = work_dir();
        let dir = tmp.path();
        fs::write(dir.join("o1"), "an earlier output").unwrap();
        fs::hard_link(dir.join("o1"), dir.join("o2")).unwrap();
        if let [a, b, ..] = files[..] {
            for (x, y, how) in [("same", "same", "one path"), ("o1", "o2", "hard links")] {
                let mut args = base();
                args.extend([a.into(), x.into(), b.into(), y.into()]);
                refused(dir, &args, &[a, b], how);
            }
        }
        if let (Some(a), Some(d)) = (files.first(), dirs.first()) {
            fs::create_dir(dir.join("out")).unwrap();
            let mut args = base();
            args.extend([
                d.to_string(),
                "out".into(),
                a.to_string(),
                "out/x.json".into(),
            ]);
            refused(
                dir,
                &args,
                &[d, a],
                "a file output inside the directory output",
            );
        }
    }
}

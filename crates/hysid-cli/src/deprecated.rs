//! Old flag spellings, kept working for one release: each is rewritten to its new name with
//! one deprecation line on stderr.
//!
//! | command | old | new |
//! |---|---|---|
//! | `identify cascade`, `identify hysteresis` | `--model FILE` (output) | `--model-out FILE` |
//! | every command with plots | `--out DIR` | `--plots DIR` |
//! | `simulate`, `generate voros`, `benchmark bouc-wen generate` | `--out FILE` | `--csv FILE` |
//! | `actuator rig` | `--out DIR` | `--data-out DIR` |

use std::ffi::OsString;

/// The new name of `flag` under the subcommand words `path`, when it is an old spelling.
fn renamed(path: &[String], flag: &str) -> Option<&'static str> {
    let path: Vec<&str> = path.iter().map(String::as_str).collect();
    match (path.as_slice(), flag) {
        (["identify", ..], "--model") => Some("--model-out"),
        (["simulate"] | ["generate", "voros"] | ["benchmark", "bouc-wen", "generate"], "--out") => {
            Some("--csv")
        }
        (["actuator", "rig"], "--out") => Some("--data-out"),
        (_, "--out") => Some("--plots"),
        _ => None,
    }
}

/// The command line with old spellings replaced (`--old VALUE` and `--old=VALUE`).
pub fn rewrite(args: Vec<OsString>) -> Vec<OsString> {
    let mut path = Vec::new();
    let mut in_path = true;
    let mut out = Vec::with_capacity(args.len());
    for (i, arg) in args.into_iter().enumerate() {
        let Some(text) = arg.to_str().map(str::to_owned) else {
            out.push(arg);
            continue;
        };
        // The subcommand words are the leading arguments before the first flag.
        if i > 0 && in_path {
            if text.starts_with('-') {
                in_path = false;
            } else {
                path.push(text.clone());
            }
        }
        let (flag, value) = match text.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
            _ => (text.clone(), None),
        };
        match renamed(&path, &flag) {
            Some(new) if flag.starts_with("--") => {
                eprintln!("warning: {flag} is deprecated here; use {new} (the old spelling goes in the next release)");
                out.push(OsString::from(match value {
                    Some(v) => format!("{new}={v}"),
                    None => new.to_string(),
                }));
            }
            _ => out.push(arg),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(line: &str) -> String {
        let args = line.split(' ').map(OsString::from).collect();
        rewrite(args)
            .into_iter()
            .map(|a| a.into_string().unwrap())
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn old_spellings_become_new_ones() {
        assert_eq!(
            run("hysid identify cascade --data d.csv --model m.json --out p"),
            "hysid identify cascade --data d.csv --model-out m.json --plots p"
        );
        assert_eq!(
            run("hysid simulate --model m.json --out s.csv"),
            "hysid simulate --model m.json --csv s.csv"
        );
        assert_eq!(
            run("hysid actuator rig --out=dir"),
            "hysid actuator rig --data-out=dir"
        );
        assert_eq!(
            run("hysid benchmark bouc-wen generate --out t.csv"),
            "hysid benchmark bouc-wen generate --csv t.csv"
        );
        assert_eq!(
            run("hysid greybox fit --model bouc-wen --out p"),
            "hysid greybox fit --model bouc-wen --plots p"
        );
    }
}

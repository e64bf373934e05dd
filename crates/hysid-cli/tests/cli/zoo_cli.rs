//! The model zoo's commands end to end: `identify operator` for every family writes a model
//! that `hysid simulate` reproduces, `compare` on the piezo record, `compensate`, and bad input
//! (one line on stderr, the documented exit code, no panic).

use crate::common::{hysid, read_json, Assert};
use hysid::model::operators::{Dahl, Family, HysteresisOperator};
use std::fs;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn repo_data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(rel)
}

fn piezo() -> PathBuf {
    repo_data("piezo/piezo_150V_1Hz.csv")
}

/// A clockwise friction loop from a known Dahl operator (σ = 12, F_c = 2, i = 1.8) over the
/// input of [`synthetic_loop`]: Dahl fits friction loops, and on the PI loop its search
/// wanders through stiff trial points for a minute before it gives up on a poor fit.
fn dahl_loop(dir: &Path) -> PathBuf {
    let path = dir.join("dahl.csv");
    let u: Vec<f64> = (0..1200)
        .map(|k| {
            let t = k as f64 / 1200.0;
            (1.0 - 0.5 * t) * (2.0 * std::f64::consts::PI * 4.0 * t).sin()
        })
        .collect();
    let y = Dahl::new(12.0, 2.0, 1.8).unwrap().simulate(&u).unwrap();
    let mut text = String::from("u,y\n");
    for (u, y) in u.iter().zip(&y) {
        text.push_str(&format!("{u},{y}\n"));
    }
    fs::write(&path, text).unwrap();
    path
}

/// A counter-clockwise loop with minor loops, from a known PI operator (u in 0..1200 samples).
fn synthetic_loop(dir: &Path) -> PathBuf {
    let path = dir.join("loop.csv");
    let mut text = String::from("t,u,y\n");
    let (r, a) = ([0.1, 0.25, 0.4, 0.6], [0.4, 0.3, 0.2, 0.1]);
    let mut z = [0.0f64; 4];
    for k in 0..1200 {
        let t = k as f64 / 1200.0;
        let u = (1.0 - 0.5 * t) * (2.0 * std::f64::consts::PI * 4.0 * t).sin()
            + 0.1 * (2.0 * std::f64::consts::PI * 23.0 * t).sin();
        let mut y = 0.5 * u + 0.1;
        for i in 0..4 {
            z[i] = (u - r[i]).max((u + r[i]).min(z[i]));
            y += a[i] * z[i];
        }
        // A smooth saturation makes the loop one no family reproduces exactly.
        let y = 2.0 * (y / 2.0).tanh();
        text.push_str(&format!("{k},{u},{y}\n"));
    }
    fs::write(&path, text).unwrap();
    path
}

fn one_line_error(out: &std::process::Output, code: i32) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "stderr: {stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    errors[0].to_string()
}

/// Every family of the registry: the `--model-out` file run by `hysid simulate` reproduces the report's fit %
/// to 1e-9 relative.
#[test]
fn every_family_saves_a_model_that_simulate_reproduces() {
    let dir = TempDir::new().unwrap();
    let data = synthetic_loop(dir.path());
    let data_ferrite = repo_data("ferrite/mnzn_ferrite_bh_loops.csv");
    let data_dahl = dahl_loop(dir.path());
    // Every family of the registry, so a new family is tested here without an edit.
    for family in Family::names() {
        // Jiles–Atherton is a magnetic model: its record is a measured B(H) loop; the
        // Coleman–Hodgdon forms get the piezo record they were made for.
        let (file, input, output) = match family {
            "jiles-atherton" => (data_ferrite.clone(), "H4_A_per_m", "B4_T"),
            "ch4" | "ch6" => (piezo(), "voltage_V", "displacement_um"),
            "dahl" => (data_dahl.clone(), "u", "y"),
            _ => (data.clone(), "u", "y"),
        };
        let (report, model, sim) = (
            dir.path().join(format!("{family}.json")),
            dir.path().join(format!("{family}.model.json")),
            dir.path().join(format!("{family}.sim.json")),
        );
        let out = hysid()
            .args(["identify", "operator", "--family", family, "--data"])
            .arg(&file)
            .args(["--input", input, "--output", output, "--json"])
            .arg(&report)
            .arg("--model-out")
            .arg(&model)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{family}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r = read_json(&report);
        assert_eq!(r["command"], "identify operator");
        let fit = r["fit"]["fit_percent"].as_f64().unwrap();
        let keys: Vec<&str> = r["model"]["parameters"][0]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        assert_eq!(
            keys.len(),
            7,
            "{family}: parameter keys {keys:?} (name, value, std, unit, fixed, lower, upper)"
        );
        hysid()
            .args(["simulate", "--model"])
            .arg(&model)
            .arg("--data")
            .arg(&file)
            .args(["--input", input, "--output", output, "--json"])
            .arg(&sim)
            .assert()
            .success();
        let again = read_json(&sim)["fit"]["fit_percent"].as_f64().unwrap();
        assert!(
            (again - fit).abs() <= 1e-9 * fit.abs(),
            "{family}: identify {fit} vs simulate {again}"
        );
    }
}

/// The piezo record: the best family of `compare` beats ch4 and ch6 fitted and validated on
/// the same 60/40 split; the report lists every family's validation fit %.
#[test]
fn piezo_compare_best_family_beats_coleman_hodgdon() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("compare.json");
    let plots = dir.path().join("plots");
    let out = hysid()
        .args(["compare", "--data"])
        .arg(piezo())
        .args([
            "--input",
            "voltage_V",
            "--output",
            "displacement_um",
            "--families",
            "pi,gpi,preisach,maxwell-slip,backlash,ch4,ch6",
            "--json",
        ])
        .arg(&json)
        .arg("--plots")
        .arg(&plots)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("first 60 %"), "{stdout}");
    let r = read_json(&json);
    assert_eq!(r["command"], "compare");
    assert_eq!(r["details"]["split"]["train"], 1200);
    let rows = r["details"]["families"].as_array().unwrap();
    assert_eq!(rows.len(), 7);
    let fit_of = |name: &str| {
        rows.iter()
            .find(|row| row["family"] == name)
            .and_then(|row| row["validation_fit_percent"].as_f64())
            .unwrap_or(f64::NEG_INFINITY)
    };
    let best = rows[0]["validation_fit_percent"].as_f64().unwrap();
    assert!(best > fit_of("ch4") && best > fit_of("ch6"), "{rows:?}");
    assert!(best > 99.0, "best validation fit {best}");
    assert_eq!(r["details"]["best"], rows[0]["family"]);
    assert_eq!(r["model"]["family"], rows[0]["family"]);
    assert!(plots.join("compare_loops.svg").is_file());
}

/// Compensation with a PI model of the piezo: the predicted output follows a reachable
/// reference; a reference beyond the reachable range is clipped, counted and warned about.
#[test]
fn compensate_tracks_and_warns_when_clipping() {
    let dir = TempDir::new().unwrap();
    let model = dir.path().join("pi.json");
    hysid()
        .args(["identify", "operator", "--family", "pi", "--data"])
        .arg(piezo())
        .args([
            "--input",
            "voltage_V",
            "--output",
            "displacement_um",
            "--model-out",
        ])
        .arg(&model)
        .assert()
        .success();
    let reference = dir.path().join("ref.csv");
    let mut text = String::from("t,r,far\n");
    for k in 0..400 {
        let s = (2.0 * std::f64::consts::PI * 2.0 * k as f64 / 400.0).sin();
        text.push_str(&format!("{k},{},{}\n", 10.0 * s, 1e9 * s.abs() - 1.0));
    }
    fs::write(&reference, text).unwrap();
    let (csv, json) = (dir.path().join("u.csv"), dir.path().join("c.json"));
    let out = hysid()
        .args(["compensate", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&reference)
        .args(["--reference", "r", "--csv"])
        .arg(&csv)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = read_json(&json);
    assert_eq!(r["command"], "compensate");
    assert_eq!(r["details"]["clipped"]["count"], 0);
    assert!(r["details"]["tracking_error"]["max"].as_f64().unwrap() < 1e-9);
    let header = fs::read_to_string(&csv).unwrap();
    assert!(header.starts_with("reference,u,predicted"), "{header}");
    // A PI operator with a0 > 0 is unbounded; the saturated Coleman–Hodgdon hysteresis (ch4)
    // is not, and its recursion limits the step |Δx| ≤ 1/α: a reference of 1e9 µm is out of
    // its reach (and this also compensates a ch4 model file).
    let preisach = dir.path().join("ch4.json");
    hysid()
        .args(["identify", "operator", "--family", "ch4", "--data"])
        .arg(piezo())
        .args([
            "--input",
            "voltage_V",
            "--output",
            "displacement_um",
            "--model-out",
        ])
        .arg(&preisach)
        .assert()
        .success();
    let out = hysid()
        .args(["compensate", "--model"])
        .arg(&preisach)
        .arg("--data")
        .arg(&reference)
        .args(["--reference", "far", "--csv"])
        .arg(&csv)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning:"))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("clipped"), "{stderr}");
    let r = read_json(&json);
    let count = r["details"]["clipped"]["count"].as_u64().unwrap();
    assert!(count > 0);
    assert_eq!(
        r["details"]["clipped"]["indices"].as_array().unwrap().len() as u64,
        count
    );
}

/// The Krasnosel'skii–Pokrovskii family on the piezo record, through every command: `compare`
/// ranks it at least about as well as Preisach on the validation part (the default fits),
/// and its model compensates the measured displacement with no clipping and an exact track.
#[test]
fn kp_compares_and_compensates_the_piezo_record() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("compare.json");
    let model = dir.path().join("kp.json");
    hysid()
        .args(["compare", "--data"])
        .arg(piezo())
        .args(["--input", "voltage_V", "--output", "displacement_um"])
        .args(["--families", "kp,preisach", "--json"])
        .arg(&json)
        .assert()
        .success();
    let r = read_json(&json);
    let fit_of = |family: &str| {
        r["details"]["families"]
            .as_array()
            .unwrap()
            .iter()
            .find(|row| row["family"] == family)
            .and_then(|row| row["validation_fit_percent"].as_f64())
            .unwrap()
    };
    let (kp, preisach) = (fit_of("kp"), fit_of("preisach"));
    assert!(kp >= preisach - 0.1, "kp {kp} % vs preisach {preisach} %");
    hysid()
        .args(["identify", "operator", "--family", "kp", "--data"])
        .arg(piezo())
        .args(["--input", "voltage_V", "--output", "displacement_um"])
        .arg("--model-out")
        .arg(&model)
        .assert()
        .success();
    let (csv, report) = (dir.path().join("u.csv"), dir.path().join("c.json"));
    hysid()
        .args(["compensate", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(piezo())
        .args(["--reference", "displacement_um", "--csv"])
        .arg(&csv)
        .arg("--json")
        .arg(&report)
        // The measured output's inverse needs commands slightly beyond the measured input at
        // a few samples, which the default limits (the fitted input range) would clip.
        .args(["--limits", "-1000:1000"])
        .assert()
        .success();
    let c = read_json(&report);
    assert_eq!(c["details"]["clipped"]["count"], 0);
    let max = c["details"]["tracking_error"]["max"].as_f64().unwrap();
    assert!(max < 1e-6, "tracking error {max} µm");
}

/// Unknown family, non-monotone threshold grid, too few reversals, a model kind that cannot
/// be inverted: each one line on stderr with exit code 1 (bad input), no output file.
#[test]
fn bad_input_is_one_line_with_exit_code_1() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("r.json");
    let identify = |family: &str, data: &Path, extra: &[&str]| {
        hysid()
            .args(["identify", "operator", "--family", family, "--data"])
            .arg(data)
            .args(["--input", "u", "--output", "y", "--json"])
            .arg(&json)
            .args(extra)
            .output()
            .unwrap()
    };
    let data = synthetic_loop(dir.path());
    let e = one_line_error(&identify("prandtl", &data, &[]), 1);
    assert!(e.contains("unknown hysteresis family 'prandtl'"), "{e}");
    let e = one_line_error(&identify("pi", &data, &["--thresholds", "0.1,0.3,0.2"]), 1);
    assert!(e.contains("not strictly increasing"), "{e}");
    let e = one_line_error(&identify("pi", &data, &["--thresholds", "0"]), 1);
    assert!(e.contains("1..=200"), "{e}");
    // A ramp never reverses: no loop to fit, for a linear and for a differential family.
    let ramp = dir.path().join("ramp.csv");
    let mut text = String::from("t,u,y\n");
    for k in 0..300 {
        text.push_str(&format!(
            "{k},{},{}\n",
            k as f64 * 0.01,
            (k as f64 * 0.01).sin()
        ));
    }
    fs::write(&ramp, text).unwrap();
    for family in ["bouc-wen", "preisach", "ch4"] {
        // A small Preisach grid, so that the sample count is not what is refused.
        let e = one_line_error(&identify(family, &ramp, &["--grid", "4"]), 1);
        assert!(
            e.contains("revers") || e.contains("excite") || e.contains("loop"),
            "{family}: {e}"
        );
    }
    assert!(!json.exists());
    // A Coleman–Hodgdon cascade cannot be inverted by compensate.
    let cascade = dir.path().join("cascade.json");
    fs::write(
        &cascade,
        r#"{"schema":"hysid.model/1","kind":"ch_cascade","hysteresis":"ch4","delay":1,
            "parameters":[
            {"name":"alpha","value":0.3,"std":null,"unit":"","fixed":false,"lower":null,"upper":null},
            {"name":"m1","value":1.0,"std":null,"unit":"","fixed":false,"lower":null,"upper":null},
            {"name":"c1","value":0.5,"std":null,"unit":"","fixed":false,"lower":null,"upper":null},
            {"name":"d","value":3.0,"std":null,"unit":"","fixed":false,"lower":null,"upper":null},
            {"name":"b1","value":1.0,"std":null,"unit":"","fixed":true,"lower":null,"upper":null},
            {"name":"a1","value":-0.5,"std":null,"unit":"","fixed":false,"lower":null,"upper":null}]}"#,
    )
    .unwrap();
    let csv = dir.path().join("u.csv");
    let out = hysid()
        .args(["compensate", "--model"])
        .arg(&cascade)
        .arg("--data")
        .arg(&data)
        .args(["--reference", "y", "--csv"])
        .arg(&csv)
        .output()
        .unwrap();
    let e = one_line_error(&out, 1);
    assert!(e.contains("not invertible: model kind 'ch_cascade'"), "{e}");
    assert!(!csv.exists());
}

/// The command line's family choices are the registry's: the help of `--family` and of
/// `--hysteresis` names every family with its title.
#[test]
fn family_help_lists_the_registry() {
    for (command, families) in [
        (["identify", "operator"], Family::ALL.to_vec()),
        (["identify", "cascade"], Family::operators().collect()),
    ] {
        let out = hysid().args(command).arg("--help").output().unwrap();
        assert!(out.status.success());
        let help = String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        for f in families {
            let entry = format!("{} ({})", f.name(), f.title());
            let entry = entry.split_whitespace().collect::<Vec<_>>().join(" ");
            assert!(help.contains(&entry), "{command:?} --help lacks {entry}");
        }
    }
}

/// Set points are a sequence, not a time series, for the hysteresis families: the loop of
/// [`synthetic_loop`] with its time column replaced by three runs at irregular moments (gaps
/// of minutes between them, steps of 1 s and 7.5 s within) fits, compares and simulates to
/// the same numbers as with its uniform time column; a model with dynamics in time still
/// refuses the gaps.
#[test]
fn set_points_at_irregular_times_are_one_history_for_the_hysteresis_families() {
    let dir = TempDir::new().unwrap();
    let uniform = synthetic_loop(dir.path());
    let text = fs::read_to_string(&uniform).unwrap();
    let mut gaps = String::from("t,u,y\n");
    let mut t = 0.0;
    for (k, line) in text.lines().skip(1).enumerate() {
        t += match k {
            400 | 800 => 600.0,
            _ if k % 3 == 0 => 7.5,
            _ => 1.0,
        };
        let rest = line.split_once(',').unwrap().1;
        gaps.push_str(&format!("{t},{rest}\n"));
    }
    let gapped = dir.path().join("gaps.csv");
    fs::write(&gapped, gaps).unwrap();
    let fit = |data: &Path, name: &str| {
        let (report, model) = (
            dir.path().join(format!("{name}.json")),
            dir.path().join(format!("{name}.model.json")),
        );
        hysid()
            .args(["identify", "operator", "--family", "pi", "--data"])
            .arg(data)
            .args(["--input", "u", "--output", "y", "-q", "--json"])
            .arg(&report)
            .arg("--model-out")
            .arg(&model)
            .assert()
            .success();
        (read_json(&report), model)
    };
    let (on_grid, _) = fit(&uniform, "uniform");
    let (irregular, model) = fit(&gapped, "gaps");
    assert_eq!(
        on_grid["model"]["parameters"],
        irregular["model"]["parameters"]
    );
    assert_eq!(
        on_grid["fit"]["fit_percent"],
        irregular["fit"]["fit_percent"]
    );
    let simulated = dir.path().join("sim.json");
    hysid()
        .args(["simulate", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&gapped)
        .args(["--input", "u", "--output", "y", "-q", "--json"])
        .arg(&simulated)
        .assert()
        .success();
    let sim = read_json(&simulated);
    let got = sim["fit"]["fit_percent"].as_f64().unwrap();
    let want = irregular["fit"]["fit_percent"].as_f64().unwrap();
    assert!((got - want).abs() < 1e-9, "simulate {got}, fit {want}");
    hysid()
        .args(["compare", "--families", "pi,backlash", "--data"])
        .arg(&gapped)
        .args(["--input", "u", "--output", "y", "-q"])
        .assert()
        .success();
    // a cascade's linear block runs in time: its records keep their uniform time
    hysid()
        .args([
            "identify",
            "cascade",
            "--hysteresis",
            "pi",
            "--na",
            "1",
            "--nb",
            "1",
        ])
        .args(["--delay", "1", "--data"])
        .arg(&gapped)
        .args(["--input", "u", "--output", "y", "-q"])
        .assert()
        .code(1)
        .stderr_contains("more than 1 % off the mean step");
}

//! All-or-nothing outputs: refusals at registration, commit, rollback, directory swap,
//! non-finite reports and cleanup on SIGTERM.

use hysid::io::atomic::{ensure_finite, ensure_finite_json, OutputSet};
use hysid::Error;
use std::fs;
use std::path::Path;

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_committed_set_replaces_every_output_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report.json");
    let plots = dir.path().join("plots");
    fs::write(&report, "old").unwrap();
    fs::create_dir(&plots).unwrap();
    fs::write(plots.join("old.svg"), "old").unwrap();

    let mut outputs = OutputSet::new(&[]).unwrap();
    let report_tmp = outputs.file(&report).unwrap();
    let plots_tmp = outputs.dir(&plots).unwrap();
    assert_eq!(report_tmp.parent(), Some(dir.path()));
    assert!(report_tmp
        .file_name()
        .unwrap()
        .to_string_lossy()
        .starts_with(".report.json.hysid-tmp-"));
    fs::write(&report_tmp, "new").unwrap();
    fs::write(plots_tmp.join("new.svg"), "new").unwrap();
    // Nothing visible changes before the commit.
    assert_eq!(fs::read_to_string(&report).unwrap(), "old");
    assert_eq!(listing(&plots), ["old.svg"]);
    outputs.commit().unwrap();

    assert_eq!(fs::read_to_string(&report).unwrap(), "new");
    // The directory was swapped, not merged: the old file is gone.
    assert_eq!(listing(&plots), ["new.svg"]);
    assert_eq!(listing(dir.path()), ["plots", "report.json"]);
}

#[test]
fn a_failed_run_leaves_previous_outputs_intact_and_no_temporaries() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("sim.csv");
    let plots = dir.path().join("plots");
    fs::write(&csv, "previous").unwrap();
    fs::create_dir(&plots).unwrap();
    fs::write(plots.join("a.svg"), "previous").unwrap();

    let run = || -> hysid::Result<()> {
        let mut outputs = OutputSet::new(&[])?;
        let tmp = outputs.file(&csv)?;
        let plot_dir = outputs.dir(&plots)?;
        fs::write(&tmp, "half").unwrap();
        fs::write(plot_dir.join("b.svg"), "half").unwrap();
        // The run fails midway: the set is dropped without a commit.
        Err(Error::InvalidData("the fit failed".into()))
    };
    assert!(run().is_err());
    assert_eq!(fs::read_to_string(&csv).unwrap(), "previous");
    assert_eq!(listing(&plots), ["a.svg"]);
    assert_eq!(listing(dir.path()), ["plots", "sim.csv"]);
}

#[test]
fn an_output_never_written_fails_the_commit_and_replaces_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.json");
    let b = dir.path().join("b.json");
    fs::write(&a, "old a").unwrap();
    let mut outputs = OutputSet::new(&[]).unwrap();
    let a_tmp = outputs.file(&a).unwrap();
    outputs.file(&b).unwrap();
    fs::write(&a_tmp, "new a").unwrap();
    let e = outputs.commit().unwrap_err().to_string();
    assert!(e.contains("b.json") && e.contains("never written"), "{e}");
    assert_eq!(fs::read_to_string(&a).unwrap(), "old a");
    assert_eq!(listing(dir.path()), ["a.json"]);
}

#[test]
fn an_output_equal_to_an_input_is_refused_whatever_its_spelling() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data.csv");
    fs::write(&data, "t,u\n0,1\n").unwrap();
    let mut outputs = OutputSet::new(&[&data]).unwrap();
    let same = dir.path().join(".").join("data.csv");
    let e = outputs.file(&same).unwrap_err().to_string();
    assert!(e.contains("is also an input"), "{e}");
    // A directory output holding the input would delete it when swapped.
    let e = outputs.dir(dir.path()).unwrap_err().to_string();
    assert!(e.contains("holds the input"), "{e}");
    assert_eq!(fs::read_to_string(&data).unwrap(), "t,u\n0,1\n");
}

#[test]
fn the_same_output_twice_or_a_file_inside_a_directory_output_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = OutputSet::new(&[]).unwrap();
    outputs.file(&dir.path().join("r.json")).unwrap();
    let e = outputs
        .file(&dir.path().join("r.json"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("clashes with the output"), "{e}");
    fs::create_dir(dir.path().join("plots")).unwrap();
    outputs.dir(&dir.path().join("plots")).unwrap();
    let e = outputs
        .file(&dir.path().join("plots").join("x.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("clashes with the output"), "{e}");
}

#[test]
fn an_unwritable_or_missing_directory_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("plain");
    fs::write(&file, "").unwrap();
    let mut outputs = OutputSet::new(&[]).unwrap();
    // A regular file as the directory: not writable into, even for root.
    let e = outputs.file(&file.join("r.json")).unwrap_err().to_string();
    assert!(e.contains("does not exist"), "{e}");
    let e = outputs.dir(&file.join("plots")).unwrap_err().to_string();
    assert!(!e.is_empty() && !e.contains('\n'), "{e}");
    let e = outputs
        .file(&dir.path().join("missing").join("r.json"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("does not exist"), "{e}");
    #[cfg(target_os = "linux")]
    {
        // procfs refuses new files even to root: the probe must catch it.
        let e = outputs
            .file(Path::new("/proc/hysid-probe-test.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("not writable"), "{e}");
    }
    assert_eq!(listing(dir.path()), ["plain"]);
}

#[test]
fn parents_created_for_a_directory_output_are_removed_when_the_run_fails() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("out").join("example1");
    {
        let mut outputs = OutputSet::new(&[]).unwrap();
        let tmp = outputs.dir(&plots).unwrap();
        fs::write(tmp.join("a.svg"), "x").unwrap();
    }
    assert!(listing(dir.path()).is_empty());
    let mut outputs = OutputSet::new(&[]).unwrap();
    let tmp = outputs.dir(&plots).unwrap();
    fs::write(tmp.join("a.svg"), "x").unwrap();
    outputs.commit().unwrap();
    assert_eq!(listing(&plots), ["a.svg"]);
}

#[test]
fn a_report_with_a_non_finite_number_is_refused_naming_its_key() {
    #[derive(serde::Serialize)]
    struct Parameter {
        value: f64,
    }
    #[derive(serde::Serialize)]
    struct Report {
        fit_percent: f64,
        parameters: std::collections::BTreeMap<String, Parameter>,
        history: Vec<Vec<f32>>,
    }
    let mut report = Report {
        fit_percent: 97.5,
        parameters: [("alpha".to_string(), Parameter { value: 0.3 })].into(),
        history: vec![vec![1.0, 2.0], vec![3.0]],
    };
    ensure_finite(&report).unwrap();
    report.history[1][0] = f32::INFINITY;
    let e = ensure_finite(&report).unwrap_err();
    assert!(matches!(e, Error::NonFiniteResult { .. }));
    assert!(e.to_string().contains("inf at 'history[1][0]'"), "{e}");
    report.parameters.get_mut("alpha").unwrap().value = f64::NAN;
    let e = ensure_finite(&report).unwrap_err().to_string();
    assert!(e.contains("NaN at 'parameters.alpha.value'"), "{e}");
    // A JSON value cannot hold NaN: json! already made it null.
    let value = serde_json::json!({"fit": f64::NAN, "ok": [1.0, 2.0]});
    assert_eq!(value["fit"], serde_json::Value::Null);
    ensure_finite_json(&value).unwrap();
}

/// Run as a child process by the next tests: registers outputs, writes the temporaries,
/// announces itself and waits to be killed. With `HYSID_SIGTERM_HANDLER` set it acts as a
/// program that cleans up on a signal (as the `hysid` command line does): its own handler
/// removes the temporaries and exits with 130. The library installs none.
#[test]
#[ignore = "helper: run only as the child of the SIGTERM tests"]
fn sigterm_child() {
    let Ok(dir) = std::env::var("HYSID_SIGTERM_DIR") else {
        return;
    };
    if std::env::var_os("HYSID_SIGTERM_HANDLER").is_some() {
        ctrlc::set_handler(|| {
            hysid::io::atomic::remove_live_temporaries();
            std::process::exit(130);
        })
        .unwrap();
    }
    let dir = Path::new(&dir);
    let mut outputs = OutputSet::new(&[]).unwrap();
    let tmp = outputs.file(&dir.join("report.json")).unwrap();
    let plots = outputs.dir(&dir.join("plots")).unwrap();
    hysid::io::atomic::write(&tmp, "new").unwrap();
    fs::write(plots.join("new.svg"), "new").unwrap();
    fs::write(dir.join("ready"), "").unwrap();
    std::thread::sleep(std::time::Duration::from_secs(60));
}

/// Starts [`sigterm_child`] over `dir` (with its handler when `handler`), waits until it
/// has written its temporaries, sends SIGTERM and returns its exit status.
#[cfg(unix)]
fn signalled_child(dir: &Path, handler: bool) -> std::process::ExitStatus {
    fs::write(dir.join("report.json"), "old").unwrap();
    fs::create_dir(dir.join("plots")).unwrap();
    let mut command = std::process::Command::new(std::env::current_exe().unwrap());
    command
        .args([
            "--ignored",
            "--exact",
            "atomic_outputs::sigterm_child",
            "--nocapture",
        ])
        .env("HYSID_SIGTERM_DIR", dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
    if handler {
        command.env("HYSID_SIGTERM_HANDLER", "1");
    }
    let mut child = command.spawn().unwrap();
    let ready = dir.join("ready");
    // Wait for the child (bounded: 30 s of 10 ms polls), then signal it.
    for _ in 0..3000 {
        if ready.exists() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(ready.exists(), "the child never got ready");
    assert!(listing(dir).iter().any(|n| n.contains("hysid-tmp")));
    let status = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let exit = child.wait().unwrap();
    fs::remove_file(&ready).unwrap();
    exit
}

#[cfg(unix)]
#[test]
fn sigterm_removes_the_temporaries_and_keeps_the_previous_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let exit = signalled_child(dir.path(), true);
    assert_eq!(exit.code(), Some(130));
    assert_eq!(listing(dir.path()), ["plots", "report.json"]);
    assert_eq!(
        fs::read_to_string(dir.path().join("report.json")).unwrap(),
        "old"
    );
    assert!(listing(&dir.path().join("plots")).is_empty());
}

/// Run as a child process by the next test: registers, creates, writes and drops or
/// commits output sets in a tight loop — a file, a directory with a file and a CSV inside
/// it — with a handler that removes the temporaries and exits with 130.
#[test]
#[ignore = "helper: run only as the child of the interrupt-at-any-moment test"]
fn churning_child() {
    let Ok(dir) = std::env::var("HYSID_CHURN_DIR") else {
        return;
    };
    ctrlc::set_handler(|| {
        hysid::io::atomic::remove_live_temporaries();
        std::process::exit(130);
    })
    .unwrap();
    let dir = Path::new(&dir);
    fs::write(dir.join("ready"), "").unwrap();
    for k in 0.. {
        let mut outputs = OutputSet::new(&[]).unwrap();
        let tmp = outputs.file(&dir.join("report.json")).unwrap();
        let plots = outputs.dir(&dir.join("plots")).unwrap();
        hysid::io::atomic::write(&tmp, "new").unwrap();
        fs::write(plots.join("a.svg"), "new").unwrap();
        hysid::data::write_csv(&plots.join("b.csv"), &["x"], &[&[1.0]]).unwrap();
        if k % 2 == 0 {
            outputs.commit().unwrap();
        }
    }
}

/// A program whose handler calls `remove_live_temporaries` leaves no temporary whatever
/// the moment of the signal — also between a registration and the creation of its
/// temporary, which the library does under the handler's lock (`OutputSet::dir`,
/// `atomic::create`). Forty signals at seeded moments into a child that does nothing but
/// register and write outputs.
#[cfg(unix)]
#[test]
fn a_signal_at_any_moment_leaves_no_temporary() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(41);
    for round in 0..40 {
        let dir = tempfile::tempdir().unwrap();
        let mut child = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--ignored",
                "--exact",
                "atomic_outputs::churning_child",
                "--nocapture",
            ])
            .env("HYSID_CHURN_DIR", dir.path())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let ready = dir.path().join("ready");
        for _ in 0..3000 {
            if ready.exists() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert!(ready.exists(), "the child never got ready");
        let moment = rng.random_range(0.0..0.05);
        std::thread::sleep(std::time::Duration::from_secs_f64(moment));
        let status = std::process::Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let exit = child.wait().unwrap();
        assert_eq!(exit.code(), Some(130), "round {round}: {exit}");
        let mut left = Vec::new();
        let mut pending = vec![dir.path().to_path_buf()];
        while let Some(d) = pending.pop() {
            for entry in fs::read_dir(&d).unwrap().flatten() {
                let name = entry.file_name().to_string_lossy().into_owned();
                if name.contains("hysid-tmp") || name.contains("hysid-probe") {
                    left.push(name);
                }
                if entry.path().is_dir() {
                    pending.push(entry.path());
                }
            }
        }
        assert!(left.is_empty(), "round {round}: temporaries left: {left:?}");
    }
}

/// A temporary is created only through its registration: any other path is refused.
#[test]
fn only_a_registered_temporary_is_created() {
    let dir = tempfile::tempdir().unwrap();
    let stray = dir.path().join(".x.hysid-tmp-0-0");
    let e = hysid::io::atomic::create(&stray).unwrap_err();
    assert!(e.to_string().contains("not a registered temporary"), "{e}");
    assert!(!stray.exists());
}

/// Signals belong to the program: an output set installs no handler, so a program without
/// one ends by the signal's default action (its hidden temporaries stay, the previous
/// outputs too), and a Python interpreter or any host keeps its own handlers.
#[cfg(unix)]
#[test]
fn the_library_installs_no_signal_handler() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let exit = signalled_child(dir.path(), false);
    assert_eq!(exit.signal(), Some(15), "{exit}");
    assert_eq!(
        fs::read_to_string(dir.path().join("report.json")).unwrap(),
        "old"
    );
    assert!(listing(dir.path()).iter().any(|n| n.contains("hysid-tmp")));
}

/// The clash of a refused registration.
fn clash(e: Error) -> hysid::error::Clash {
    match e {
        Error::OutputClash(c) => c,
        other => panic!("expected an output clash, got {other}"),
    }
}

#[cfg(unix)]
#[test]
fn an_input_is_refused_through_links_dotdot_and_inside_an_input_directory() {
    use hysid::error::ClashKind;
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    let data = root.join("data");
    fs::create_dir(&data).unwrap();
    fs::write(data.join("set1.csv"), "t,u\n0,1\n").unwrap();
    fs::write(root.join("model.json"), "{}").unwrap();
    fs::create_dir(root.join("sub")).unwrap();
    fs::hard_link(data.join("set1.csv"), root.join("hard.csv")).unwrap();
    std::os::unix::fs::symlink(root.join("model.json"), root.join("link.json")).unwrap();
    let mut outputs = OutputSet::new(&[&data, &root.join("model.json")]).unwrap();
    // A file read from inside the input directory, spelled through `..`.
    let c = clash(
        outputs
            .file(&root.join("sub/../data/set1.csv"))
            .unwrap_err(),
    );
    assert_eq!(
        (c.kind, c.other.as_path()),
        (ClashKind::Input, data.as_path())
    );
    assert!(c.to_string().contains("is also an input"), "{c}");
    // A hard link of it, and a symbolic link to the other input.
    let c = clash(outputs.file(&root.join("hard.csv")).unwrap_err());
    assert_eq!(c.file, data.join("set1.csv"));
    let c = clash(outputs.dir(&root.join("link.json")).unwrap_err());
    assert_eq!(c.other, root.join("model.json"));
    // The input directory itself, and a directory holding it.
    let c = clash(outputs.dir(&data).unwrap_err());
    assert_eq!(c.kind, ClashKind::HoldsInput);
    let c = clash(outputs.dir(root).unwrap_err());
    assert_eq!(c.kind, ClashKind::HoldsInput);
    // A new file beside the inputs, or inside the input directory, is no clash.
    outputs.file(&data.join("report.json")).unwrap();
    outputs.file(&root.join("model-out.json")).unwrap();
    assert_eq!(
        fs::read_to_string(data.join("set1.csv")).unwrap(),
        "t,u\n0,1\n"
    );
}

#[test]
fn outputs_that_are_one_file_are_refused_by_identity() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    fs::write(root.join("a.json"), "old").unwrap();
    fs::hard_link(root.join("a.json"), root.join("b.json")).unwrap();
    let mut outputs = OutputSet::new(&[]).unwrap();
    outputs.file(&root.join("a.json")).unwrap();
    let c = clash(outputs.file(&root.join("b.json")).unwrap_err());
    assert_eq!(c.other, root.join("a.json"));
    // A directory registered first holds a file registered after it, even before the
    // directory exists.
    let mut outputs = OutputSet::new(&[]).unwrap();
    outputs.dir(&root.join("new/plots")).unwrap();
    let c = clash(outputs.file(&root.join("new/plots/x.json")).unwrap_err());
    assert!(c.to_string().contains("clashes with the output"), "{c}");
}

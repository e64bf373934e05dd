//! The cache of compiled equation models (`model/greybox/native/object.rs`) against planted
//! code: a library whose constructor leaves a mark is put in the cache — with a MAC forged
//! from the cache's own key under a directory, entry or key open to others (or of another
//! owner), or in the place of hysid's library keeping hysid's MAC — and the mark must not
//! appear, the fit must compile its code afresh and give the genuine figures. A control run
//! shows the plant does run when nothing is wrong with the cache but the forged MAC, so the
//! checks, not a broken plant, keep it out. And `CC` with arguments (`env cc`, `ccache cc`)
//! compiles the native code.

use crate::common::{hysid, read_json, Assert};
use std::fs;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::Command;
use tempfile::TempDir;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fit of the cascaded tanks' equation file by the C route, with this cache and compiler,
/// its report written to `report`.
fn fit(cache: &Path, cc: &str, report: &Path) -> Command {
    let mut cmd = hysid();
    cmd.env("HYSID_EVALUATOR", "cc")
        .env("HYSID_CACHE_DIR", cache)
        .env("CC", cc)
        .args(["-q", "greybox", "fit", "--model-file"])
        .arg(root().join("examples/equations/cascaded_tanks.toml"))
        .arg("--data")
        .arg(root().join("data/cascaded-tanks/estimation.csv"))
        .args(["--input", "u_V", "--output", "y_V", "--starts", "1"])
        .args(["--substeps", "2", "--json"])
        .arg(report);
    cmd
}

/// The report's `details.evaluation`.
fn evaluation(report: &Path) -> String {
    read_json(report)["details"]["evaluation"]
        .as_str()
        .unwrap()
        .to_string()
}

/// The fitted parameters and the fit's figures.
fn figures(report: &Path) -> (serde_json::Value, serde_json::Value) {
    let r = read_json(report);
    (r["model"]["parameters"].clone(), r["fit"].clone())
}

/// The names of the cache's entries (`native/NAME.so`).
fn entries(cache: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(cache.join("native"))
        .unwrap()
        .filter_map(|e| {
            let file = e.unwrap().file_name().into_string().unwrap();
            file.strip_suffix(".so").map(str::to_string)
        })
        .collect();
    names.sort();
    names
}

/// A shared library whose constructor creates the file `marker`.
fn planted_library(dir: &Path, marker: &Path) -> Vec<u8> {
    let (c, so) = (dir.join("planted.c"), dir.join("planted.so"));
    fs::write(
        &c,
        format!(
            "#include <stdio.h>\n__attribute__((constructor)) static void plant(void) {{\n  \
             FILE *f = fopen(\"{}\", \"w\");\n  if (f) fclose(f);\n}}\n",
            marker.display()
        ),
    )
    .unwrap();
    let status = Command::new("cc")
        .args(["-shared", "-fPIC", "-o"])
        .arg(&so)
        .arg(&c)
        .status()
        .unwrap();
    assert!(status.success(), "cc failed on the planted library");
    fs::read(so).unwrap()
}

/// The MAC of the entry `name` with these library bytes, as hysid computes it: keyed BLAKE3
/// of the name and the bytes, under the cache's key (read from it: only its owner can).
fn forged_mac(cache: &Path, name: &str, bytes: &[u8]) -> String {
    let key: [u8; 32] = fs::read(cache.join("key")).unwrap().try_into().unwrap();
    let mut hasher = blake3::Hasher::new_keyed(&key);
    hasher.update(name.as_bytes());
    hasher.update(bytes);
    hasher.finalize().to_hex().to_string()
}

/// Sets the mode of `path`.
fn chmod(path: &Path, mode: u32) {
    fs::set_permissions(path, fs::Permissions::from_mode(mode)).unwrap();
}

/// Whether the tests run as root (who can give a file to another user).
fn root_user(dir: &Path) -> bool {
    let probe = dir.join("probe");
    fs::write(&probe, "").unwrap();
    fs::metadata(&probe).unwrap().uid() == 0
}

/// One run against a cache that must be refused: the mark is not made, the code is compiled
/// now (privately: the cache is left as it was), with a one-line warning, and the figures
/// are the genuine ones.
fn refused(
    cache: &Path,
    dir: &Path,
    marker: &Path,
    genuine: &(serde_json::Value, serde_json::Value),
    case: &str,
) {
    let before = entries(cache);
    let report = dir.join(format!("{case}.json"));
    let out = fit(cache, "cc", &report)
        .assert()
        .success()
        .get_output()
        .clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!marker.exists(), "{case}: the planted library ran");
    let how = evaluation(&report);
    assert!(
        how.starts_with("native code (compiled now: "),
        "{case}: {how}"
    );
    assert_eq!(&figures(&report), genuine, "{case}");
    assert!(
        stderr.contains("hysid: warning: native-code cache not used: ")
            // Each warning one line: the cache's, and the fit's own (the report's, e.g. the
            // hold check on this band-limited record).
            && stderr
                .lines()
                .all(|l| l.starts_with("hysid: warning: ") || l.starts_with("warning: ")),
        "{case}: {stderr}"
    );
    assert_eq!(
        entries(cache),
        before,
        "{case}: a refused cache was written"
    );
}

/// (a) a cache directory, the entries' libraries or MACs, or the key open to others, (b) a
/// directory or the libraries of another owner: the planted library, its MAC forged with the
/// cache's key, never runs.
#[test]
fn a_planted_library_never_runs_from_a_cache_others_could_write() {
    let dir = TempDir::new().unwrap();
    let cache = dir.path().join("cache");
    let marker = dir.path().join("constructor-ran");
    let genuine_report = dir.path().join("genuine.json");
    fit(&cache, "cc", &genuine_report).assert().success();
    assert!(evaluation(&genuine_report).starts_with("native code (compiled now: "));
    let genuine = figures(&genuine_report);
    let native = cache.join("native");
    let names = entries(&cache);
    assert!(!names.is_empty());
    let planted = planted_library(dir.path(), &marker);
    for name in &names {
        fs::write(native.join(format!("{name}.so")), &planted).unwrap();
        fs::write(
            native.join(format!("{name}.mac")),
            forged_mac(&cache, name, &planted),
        )
        .unwrap();
    }

    // Control: with the MAC forged and nothing else wrong, hysid loads the plant (and fails:
    // it has none of the model's functions) — so a missing mark below is the checks' doing.
    let control = dir.path().join("control.json");
    let _ = fit(&cache, "cc", &control).output().unwrap();
    assert!(marker.exists(), "control: the planted library did not run");
    fs::remove_file(&marker).unwrap();

    // Each case opens (or gives away) these paths, runs, and closes them again; an entry's
    // case takes every entry, since each is looked up on its own.
    let libraries: Vec<PathBuf> = names
        .iter()
        .map(|name| native.join(format!("{name}.so")))
        .collect();
    let macs: Vec<PathBuf> = names
        .iter()
        .map(|name| native.join(format!("{name}.mac")))
        .collect();
    let key = cache.join("key");
    let cases: [(&[PathBuf], u32, u32, &str); 5] = [
        (
            std::slice::from_ref(&native),
            0o777,
            0o700,
            "native-dir-writable-by-others",
        ),
        (
            std::slice::from_ref(&cache),
            0o770,
            0o700,
            "base-dir-writable-by-the-group",
        ),
        (&libraries, 0o666, 0o700, "library-writable-by-others"),
        (&macs, 0o620, 0o600, "mac-writable-by-the-group"),
        (&[key], 0o640, 0o600, "key-readable-by-the-group"),
    ];
    for (paths, open, closed, case) in cases {
        paths.iter().for_each(|p| chmod(p, open));
        refused(&cache, dir.path(), &marker, &genuine, case);
        paths.iter().for_each(|p| chmod(p, closed));
    }

    if root_user(dir.path()) {
        let owners: [(&[PathBuf], &str); 2] = [
            (std::slice::from_ref(&native), "native-dir-of-uid-65534"),
            (&libraries, "library-of-uid-65534"),
        ];
        for (paths, case) in owners {
            let give = |uid| {
                for p in paths {
                    std::os::unix::fs::chown(p, Some(uid), None).unwrap();
                }
            };
            give(65534);
            refused(&cache, dir.path(), &marker, &genuine, case);
            give(0);
        }
    } else {
        println!(
            "wrong-owner cases skipped: not root, so the test cannot give a file to another \
             user"
        );
    }

    // With everything closed again, the forged plant is loaded once more: the cases above
    // were refused for what each changed, not for something left over.
    let _ = fit(&cache, "cc", &control).output().unwrap();
    assert!(
        marker.exists(),
        "control after the cases: the plant did not run"
    );
}

/// (c) a library put in the place of hysid's, hysid's MAC kept: its MAC does not match, so it
/// is never loaded (the mark is not made); the fit compiles afresh, gives the genuine
/// figures, and replaces the entry, which the next fit loads.
#[test]
fn a_replaced_library_fails_its_mac_and_is_compiled_again() {
    let dir = TempDir::new().unwrap();
    let cache = dir.path().join("cache");
    let marker = dir.path().join("constructor-ran");
    let genuine_report = dir.path().join("genuine.json");
    fit(&cache, "cc", &genuine_report).assert().success();
    let genuine = figures(&genuine_report);
    let native = cache.join("native");
    let planted = planted_library(dir.path(), &marker);
    for name in entries(&cache) {
        fs::write(native.join(format!("{name}.so")), &planted).unwrap();
    }

    let replaced = dir.path().join("replaced.json");
    let out = fit(&cache, "cc", &replaced)
        .assert()
        .success()
        .get_output()
        .clone();
    assert!(!marker.exists(), "the replaced library ran");
    let how = evaluation(&replaced);
    assert!(how.starts_with("native code (compiled now: "), "{how}");
    assert_eq!(figures(&replaced), genuine);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("does not match its MAC"), "{stderr}");

    let again = dir.path().join("again.json");
    fit(&cache, "cc", &again).assert().success();
    assert_eq!(evaluation(&again), "native code (loaded from the cache)");
    assert_eq!(figures(&again), genuine);
    assert!(!marker.exists());
}

/// The directories hysid makes are 0700, the key and MACs 0600, the libraries 0700.
#[test]
fn the_cache_is_made_private() {
    let dir = TempDir::new().unwrap();
    let cache = dir.path().join("new").join("cache");
    fit(&cache, "cc", &dir.path().join("r.json"))
        .assert()
        .success();
    let mode = |p: &Path| fs::metadata(p).unwrap().mode() & 0o777;
    assert_eq!(mode(&dir.path().join("new")), 0o700);
    assert_eq!(mode(&cache), 0o700);
    assert_eq!(mode(&cache.join("native")), 0o700);
    assert_eq!(mode(&cache.join("key")), 0o600);
    assert_eq!(fs::metadata(cache.join("key")).unwrap().len(), 32);
    for name in entries(&cache) {
        assert_eq!(
            mode(&cache.join("native").join(format!("{name}.so"))),
            0o700
        );
        assert_eq!(
            mode(&cache.join("native").join(format!("{name}.mac"))),
            0o600
        );
    }
}

/// `CC` with arguments, as make reads it: `env cc` (and `ccache cc` where ccache is
/// installed) compiles the native code, which the report says, with the figures of `cc`.
#[test]
fn a_compiler_with_arguments_compiles_the_native_code() {
    let dir = TempDir::new().unwrap();
    let plain = dir.path().join("cc.json");
    fit(&dir.path().join("cache-cc"), "cc", &plain)
        .assert()
        .success();
    let ccache = Command::new("ccache")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    let mut compilers = vec!["env cc"];
    if ccache {
        compilers.push("ccache cc");
    } else {
        println!("CC=\"ccache cc\" skipped: ccache is not installed");
    }
    for (k, cc) in compilers.into_iter().enumerate() {
        let report = dir.path().join(format!("{k}.json"));
        fit(&dir.path().join(format!("cache-{k}")), cc, &report)
            .assert()
            .success();
        let how = evaluation(&report);
        assert!(
            how.starts_with("native code (compiled now: "),
            "CC={cc}: {how}"
        );
        assert_eq!(figures(&report), figures(&plain), "CC={cc}");
    }
}

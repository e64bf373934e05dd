//! `docs/architecture.md` tells a newcomer where things are: every repository path it names
//! in backticks must exist, so the document cannot drift from the tree unnoticed.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every file and directory of the repository (relative, `/`-separated), build output and
/// version control left out.
fn tree(root: &Path) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut pending = vec![PathBuf::new()];
    while let Some(dir) = pending.pop() {
        for entry in std::fs::read_dir(root.join(&dir)).unwrap() {
            let entry = entry.unwrap();
            let name = entry.file_name().to_string_lossy().into_owned();
            if dir.as_os_str().is_empty() && matches!(name.as_str(), "target" | ".git") {
                continue;
            }
            let path = dir.join(&name);
            found.insert(path.to_string_lossy().replace('\\', "/"));
            if entry.file_type().unwrap().is_dir() {
                pending.push(path);
            }
        }
    }
    found
}

/// The first segments a repository path may start with.
const TOP: [&str; 10] = [
    "crates", "docs", "tools", "examples", "bench", "data", ".ci", "src", "tests", "unit",
];

/// The backticked spans of `text` that are repository paths: a `/` inside, no blanks, only
/// path characters, not an option (`--input/--output`), not absolute (`/proc/…`), and either
/// a file with an extension, a directory (a trailing `/`) or a path from a top-level
/// directory (so `hysid.model/1`, a schema name, is not one).
fn paths(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (i, span) in text.split('`').enumerate() {
        if i % 2 == 0 || !span.contains('/') || span.starts_with('-') || span.starts_with('/') {
            continue;
        }
        let pathlike = span
            .chars()
            .all(|c| c.is_alphanumeric() || "_-./…".contains(c));
        if !pathlike {
            continue;
        }
        let last = span.trim_end_matches('/').rsplit('/').next().unwrap_or("");
        let file = last.rsplit_once('.').is_some_and(|(stem, ext)| {
            !stem.is_empty() && ext.chars().all(|c| c.is_ascii_lowercase())
        });
        let first = span
            .trim_start_matches("…/")
            .split('/')
            .next()
            .unwrap_or("");
        if file || span.ends_with('/') || TOP.contains(&first) {
            out.push(span.to_string());
        }
    }
    out
}

/// Whether `path` names something in `tree`: from the root, from a crate's `src/`, or as
/// the tail of a longer path (`object/cache.rs`, `…/unit/identify/operators/kp.rs`).
fn exists(tree: &BTreeSet<String>, path: &str) -> bool {
    let path = path.trim_end_matches('/');
    let tail = path.trim_start_matches('…');
    let tail = if tail.starts_with('/') {
        tail.to_string()
    } else {
        format!("/{tail}")
    };
    tree.contains(path) || tree.iter().any(|p| p.ends_with(&tail))
}

#[test]
fn every_path_in_the_architecture_document_exists() {
    let root = root();
    let text = std::fs::read_to_string(root.join("docs/architecture.md")).unwrap();
    let tree = tree(&root);
    let named = paths(&text);
    assert!(named.len() > 50, "only {} paths found", named.len());
    let missing: Vec<&String> = named.iter().filter(|p| !exists(&tree, p)).collect();
    assert!(
        missing.is_empty(),
        "docs/architecture.md names paths that do not exist: {missing:?}"
    );
}

/// The extraction itself: what is a path and what is not, and a missing one is caught.
#[test]
fn the_path_extraction_tells_paths_from_other_spans() {
    let text = "`crates/hysid/src/lib.rs` `--input/--output` `/proc/meminfo` `hysid.model/1` \
                `docs/` `object/cache.rs` `…/unit/model/operators/pi.rs` `a b/c.rs` \
                `identify/prandtl_ishlinskii.rs` `Error::Io`";
    assert_eq!(
        paths(text),
        [
            "crates/hysid/src/lib.rs",
            "docs/",
            "object/cache.rs",
            "…/unit/model/operators/pi.rs",
            "identify/prandtl_ishlinskii.rs"
        ]
    );
    let tree = tree(&root());
    assert!(exists(&tree, "crates/hysid/src/lib.rs") && exists(&tree, "docs/"));
    assert!(exists(&tree, "object/cache.rs"));
    assert!(exists(&tree, "…/unit/model/operators/pi.rs"));
    assert!(!exists(&tree, "identify/prandtl_ishlinskii.rs"));
    assert!(!exists(&tree, "model/greybox/native/jit/"));
}

//! The memory and work limits a request is checked against before it starts.
//!
//! The library estimates a request ([`hysid::identify::budget::Work`]); this module compares
//! the estimate with
//!
//! * **memory**: the machine's available memory (`MemAvailable` of `/proc/meminfo`), or
//!   [`FALLBACK_MEMORY`] where that cannot be read — always refused when exceeded;
//! * **work**: [`WORK_BUDGET`] model steps — refused unless `--allow-long` is given.
//!
//! Both refusals are one line giving the figure and the limit.

use anyhow::{bail, Result};
use hysid::identify::budget::Work;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::OnceLock;

/// The work budget: 10¹⁰ model steps (about a few minutes on one core for the built-in models).
pub const WORK_BUDGET: u64 = 10_000_000_000;

/// The memory limit where `/proc/meminfo` cannot be read: 4 GiB.
pub const FALLBACK_MEMORY: u64 = 4 << 30;

static ALLOW_LONG: OnceLock<bool> = OnceLock::new();

/// The estimates checked so far (model steps), summed.
static ESTIMATED: AtomicU64 = AtomicU64::new(0);

/// The model steps the run's budget checks estimated, summed; `None` before any check.
pub fn estimated() -> Option<u64> {
    Some(ESTIMATED.load(Relaxed)).filter(|&e| e > 0)
}

/// Records `--allow-long` for the run (called once by `main`).
pub fn init(allow_long: bool) {
    let _ = ALLOW_LONG.set(allow_long);
}

/// Bytes of memory available to a new allocation.
pub fn available_memory() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| mem_available(&text))
        .unwrap_or(FALLBACK_MEMORY)
}

/// `MemAvailable` of a `/proc/meminfo` text, in bytes.
fn mem_available(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Refuses `work` (what the request is, e.g. "the grey-box fit") when it needs more memory
/// than is available, or more work than the budget without `--allow-long`.
pub fn check(what: &str, work: Work) -> Result<()> {
    ESTIMATED.fetch_add(work.evaluations, Relaxed);
    check_against(
        what,
        work,
        available_memory(),
        *ALLOW_LONG.get().unwrap_or(&false),
    )
}

fn check_against(what: &str, work: Work, memory: u64, allow_long: bool) -> Result<()> {
    if work.bytes > memory {
        bail!(
            "{what} would need about {} of memory but {} is available; use a shorter record \
             or fewer sub-steps",
            human_bytes(work.bytes),
            human_bytes(memory)
        );
    }
    if work.evaluations > WORK_BUDGET && !allow_long {
        bail!(
            "{what} would take about {:.1e} model steps, over the budget of {:.0e}; reduce the \
             starts, replicates, sub-steps or samples, or pass --allow-long to run it anyway",
            work.evaluations as f64,
            WORK_BUDGET as f64
        );
    }
    Ok(())
}

/// Bytes in GB/MB for a message.
fn human_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.0} MB", (b / 1e6).max(1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meminfo_is_read_in_kib() {
        let text = "MemTotal:  8000 kB\nMemAvailable:    2048 kB\n";
        assert_eq!(mem_available(text), Some(2048 * 1024));
        assert_eq!(mem_available("MemTotal: 1 kB\n"), None);
    }

    #[test]
    fn memory_is_always_refused_work_only_without_allow_long() {
        let big = Work {
            bytes: 13_000_000_000,
            evaluations: 1,
        };
        let err = check_against("the fit", big, 8_000_000_000, true).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the fit would need about 13.0 GB of memory but 8.0 GB is available; use a shorter \
             record or fewer sub-steps"
        );
        let long = Work {
            bytes: 1,
            evaluations: WORK_BUDGET + 1,
        };
        assert!(check_against("the fit", long, 8_000_000_000, false).is_err());
        assert!(check_against("the fit", long, 8_000_000_000, true).is_ok());
    }
}

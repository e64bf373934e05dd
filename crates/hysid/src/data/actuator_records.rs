//! The data sets of the actuator experiments of Gunnar et al. (2006) on disk: one CSV file a
//! data set (`dataset1.csv` … `dataset8.csv`, columns time, motor torque, motor angle), as the
//! virtual rig writes them and the three-step identification reads them.

use super::{CsvSpec, IdData};
use crate::{Error, Result};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The columns of a data-set file: time \[s\], motor torque [N·m], motor angle \[rad\].
pub const COLUMNS: [&str; 3] = ["t_s", "tau_Nm", "theta_rad"];

/// The file of data set `set` in a data directory: `datasetK.csv`.
pub fn data_set_path(dir: &Path, set: usize) -> PathBuf {
    dir.join(format!("dataset{set}.csv"))
}

/// Reads data sets 1–8 from `dir` (`dataset1.csv` … `dataset8.csv`, columns [`COLUMNS`]).
///
/// Fails with [`Error::InvalidData`] naming every missing file.
pub fn read_data_sets(dir: &Path) -> Result<BTreeMap<usize, Record>> {
    let missing: Vec<String> = (1..=8)
        .map(|s| data_set_path(dir, s))
        .filter(|p| !p.is_file())
        .map(|p| p.display().to_string())
        .collect();
    if !missing.is_empty() {
        return Err(Error::InvalidData(format!(
            "missing {} (the procedure needs dataset1.csv to dataset8.csv, columns {})",
            missing.join(", "),
            COLUMNS.join(", ")
        )));
    }
    let spec = CsvSpec {
        inputs: vec![COLUMNS[1].into()],
        outputs: vec![COLUMNS[2].into()],
        time: Some(COLUMNS[0].into()),
        ts: None,
        ..CsvSpec::default()
    };
    (1..=8)
        .map(|set| {
            let data = IdData::from_csv(&data_set_path(dir, set), &spec)?;
            let exp = data.experiment(0);
            Ok((
                set,
                Record {
                    ts: data.ts(),
                    torque: exp.input(0).to_vec(),
                    angle: exp.output(0).to_vec(),
                },
            ))
        })
        .collect()
}

/// One measured data set: motor torque and motor angle.
#[derive(Clone, Debug)]
pub struct Record {
    /// Sample time \[s\].
    pub ts: f64,
    /// Motor torque τ [N·m].
    pub torque: Vec<f64>,
    /// Motor angle θ \[rad\].
    pub angle: Vec<f64>,
}

//! Writes the streaming benches' models ([`hysid_bench::stream_models`]) as model files
//! (`hysid.model/1`, sample time [`hysid_bench::STREAM_TS`], columns `u` → `y`) into the
//! directory given as the argument, one `NAME.json` each, for `bench/export_steps.sh` to
//! export as C.
//!
//! `cargo run --release -p hysid-bench --example stream_models -- DIR`

use hysid::model::saved::Columns;
use hysid_bench::{stream_models, STREAM_TS};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .ok_or("usage: stream_models DIR (the directory of the model files)")?,
    );
    std::fs::create_dir_all(&dir)?;
    for (name, model) in stream_models() {
        let columns = Columns {
            inputs: vec!["u".into()],
            outputs: vec!["y".into()],
        };
        let file = model.to_file().with_data(STREAM_TS, columns);
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, serde_json::to_string_pretty(&file)?)?;
        println!("{}", path.display());
    }
    Ok(())
}

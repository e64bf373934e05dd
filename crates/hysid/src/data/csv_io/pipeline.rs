//! Reading CSV records on a second thread while the caller parses the previous batch.
//!
//! Splitting a file into records (quotes, line ends, field counts) and turning cells into
//! numbers take about the same time on long numeric files; with two threads they overlap.
//! Batches of reused [`ByteRecord`]s circulate between the two sides, so neither allocates per
//! row, and the caller sees every record in file order, exactly as a sequential loop would.

use csv::{ByteRecord, Reader};
use std::io::Read;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

/// Records per batch.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const BATCH: usize = 4096;

/// A batch of records: the first `len` are filled; `error` ends the file after them.
struct Batch {
    records: Vec<ByteRecord>,
    len: usize,
    error: Option<csv::Error>,
}

impl Batch {
    fn new() -> Self {
        Self {
            records: vec![ByteRecord::new(); BATCH],
            len: 0,
            error: None,
        }
    }

    /// Reads up to [`BATCH`] records; false once the file is exhausted or failed.
    fn fill<R: Read>(&mut self, reader: &mut Reader<R>) -> bool {
        self.len = 0;
        while self.len < BATCH {
            match reader.read_byte_record(&mut self.records[self.len]) {
                Ok(true) => self.len += 1,
                Ok(false) => return false,
                Err(e) => {
                    self.error = Some(e);
                    return false;
                }
            }
        }
        true
    }
}

/// Calls `parse` on every batch of remaining records in order; stops at the first error of
/// `parse` (returned as `Ok(Err(..))`) or of the reader (returned as `Err`, after every
/// record before it was parsed). Two threads when rayon has two, else one.
pub(super) fn for_each_batch<R: Read + Send, E>(
    reader: &mut Reader<R>,
    mut parse: impl FnMut(&[ByteRecord]) -> Result<(), E>,
) -> Result<Result<(), E>, csv::Error> {
    if rayon::current_num_threads() < 2 {
        let mut batch = Batch::new();
        loop {
            let more = batch.fill(reader);
            if let Err(e) = parse(&batch.records[..batch.len]) {
                return Ok(Err(e));
            }
            if let Some(error) = batch.error.take() {
                return Err(error);
            }
            if !more {
                return Ok(Ok(()));
            }
        }
    }
    let (full_tx, full_rx) = sync_channel::<Batch>(2);
    let (empty_tx, empty_rx) = sync_channel::<Batch>(3);
    std::thread::scope(|scope| {
        scope.spawn(move || produce(reader, empty_rx, full_tx));
        consume(full_rx, empty_tx, parse)
    })
}

/// The reading side: fills the batches it is handed and passes them on.
fn produce<R: Read>(reader: &mut Reader<R>, empty: Receiver<Batch>, full: SyncSender<Batch>) {
    let mut more = true;
    while more {
        let mut batch = empty.recv().unwrap_or_else(|_| Batch::new());
        more = batch.fill(reader);
        // A send fails only when the parser stopped; nothing more is wanted then.
        if full.send(batch).is_err() {
            return;
        }
    }
}

/// The parsing side. It owns its ends of both channels, so returning (on an error too) drops
/// them and releases a reader blocked on either.
fn consume<E>(
    full: Receiver<Batch>,
    empty: SyncSender<Batch>,
    mut parse: impl FnMut(&[ByteRecord]) -> Result<(), E>,
) -> Result<Result<(), E>, csv::Error> {
    for _ in 0..3 {
        // Cannot block: the channel has room for all three.
        let _ = empty.send(Batch::new());
    }
    for mut batch in full {
        if let Err(e) = parse(&batch.records[..batch.len]) {
            return Ok(Err(e));
        }
        if let Some(error) = batch.error.take() {
            return Err(error);
        }
        let _ = empty.send(batch);
    }
    Ok(Ok(()))
}

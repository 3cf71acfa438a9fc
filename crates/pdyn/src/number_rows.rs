//! Rows of numbers formatted and written beside the run, on another core.
//!
//! A streamed table ([`crate::stream::RowFile`]) used to be formatted by the thread that
//! integrates: the 100-link chain's 4,286 rows of 402 numbers are 1.7·10⁶ shortest
//! round-trip decimals, about an eighth of its `pdyn run`. [`NumberRows`] takes whole rows as
//! numbers and hands them, a batch at a time, to a writer thread that formats and writes
//! them, in order, with the same bytes ([`crate::output::append_number`]). A table smaller
//! than one batch, a machine with one core, and WebAssembly never start the thread: the rows
//! are formatted in place, as before.
//!
//! What [`crate::stream::RowFile`] promises still holds: the file only ever ends with a whole
//! row, [`NumberRows::sync`] returns the length a checkpoint records, and a write error
//! stops the run at the next row handed over (the writer raises a flag the integrating thread
//! reads at each row), with the error the writer met.

use crate::stream::RowFile;
use crate::Error;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Arc;
use std::thread::JoinHandle;

/// Numbers per batch handed to the writer: about 170 KiB of text, a few hundred rows of a
/// large model, a few thousand of a small one.
const BATCH: usize = 8_192;

/// Batches in flight at most (the integration waits beyond: memory stays bounded when the
/// disk is slower than the run).
const IN_FLIGHT: usize = 4;

/// Whole rows of numbers into a [`RowFile`], formatted on a writer thread once the table
/// outgrows one batch.
pub struct NumberRows {
    /// The file's path, for an error when the writer thread is lost.
    path: std::path::PathBuf,
    pending: Vec<f64>,
    width: usize,
    state: State,
}

enum State {
    /// Formatting in place.
    Inline(RowFile),
    Writer(Writer),
    /// The writer's thread ended without handing the file back (it panicked).
    Lost,
}

struct Writer {
    jobs: SyncSender<Job>,
    replies: Receiver<Result<u64, Error>>,
    failed: Arc<AtomicBool>,
    thread: JoinHandle<Option<RowFile>>,
}

enum Job {
    /// The file, the writer's first job.
    File(RowFile),
    Rows(Vec<f64>),
    /// Flush (and with `true`, sync) and reply with the file's length or the error.
    Flush(bool),
}

impl NumberRows {
    /// Rows of `width` numbers into `file`.
    pub fn new(file: RowFile, width: usize) -> NumberRows {
        NumberRows {
            path: file.path().to_path_buf(),
            pending: Vec::with_capacity(BATCH + width),
            width: width.max(1),
            state: State::Inline(file),
        }
    }

    /// Appends one row (its length the table's width). An error is the writer's, met on an
    /// earlier batch: the rows after it are not written.
    pub fn row(&mut self, row: &[f64]) -> Result<(), Error> {
        debug_assert_eq!(row.len(), self.width);
        self.pending.extend_from_slice(row);
        if self.pending.len() >= BATCH {
            self.hand_over()?;
        }
        match &self.state {
            State::Writer(w) if w.failed.load(Ordering::Relaxed) => self.flush().map(|_| ()),
            _ => Ok(()),
        }
    }

    /// Writes the rows held so far; the file's length after them.
    pub fn flush(&mut self) -> Result<u64, Error> {
        self.finish_rows(false)
    }

    /// [`NumberRows::flush`], then forced to the disk (before a checkpoint names the length).
    pub fn sync(&mut self) -> Result<u64, Error> {
        self.finish_rows(true)
    }

    /// Whether rows are formatted on a writer thread (the table outgrew one batch on a
    /// machine with more than one core).
    pub fn on_writer_thread(&self) -> bool {
        matches!(self.state, State::Writer(_))
    }

    fn finish_rows(&mut self, sync: bool) -> Result<u64, Error> {
        if let State::Inline(file) = &mut self.state {
            format_rows(file, &self.pending, self.width)?;
            self.pending.clear();
            if sync {
                file.sync()?;
            } else {
                file.flush()?;
            }
            return Ok(file.len());
        }
        self.hand_over()?;
        let State::Writer(w) = &self.state else {
            return Err(lost(&self.path));
        };
        if w.jobs.send(Job::Flush(sync)).is_err() {
            return Err(self.writer_ended());
        }
        match w.replies.recv() {
            Ok(reply) => reply,
            Err(_) => Err(self.writer_ended()),
        }
    }

    /// Sends the pending rows to the writer, starting it if this is the first batch.
    fn hand_over(&mut self) -> Result<(), Error> {
        if self.pending.is_empty() {
            return Ok(());
        }
        if let State::Inline(_) = self.state {
            if !self.start_writer() {
                let State::Inline(file) = &mut self.state else {
                    return Err(lost(&self.path));
                };
                let done = format_rows(file, &self.pending, self.width);
                self.pending.clear();
                return done;
            }
        }
        let batch = std::mem::replace(&mut self.pending, Vec::with_capacity(BATCH + self.width));
        match &self.state {
            State::Writer(w) => {
                if w.jobs.send(Job::Rows(batch)).is_err() {
                    return Err(self.writer_ended());
                }
                Ok(())
            }
            _ => Err(lost(&self.path)),
        }
    }

    /// Moves the file to a writer thread; false (the file kept here) where there is no second
    /// core or no threads.
    fn start_writer(&mut self) -> bool {
        if cfg!(target_arch = "wasm32")
            || std::thread::available_parallelism().map_or(true, |n| n.get() < 2)
        {
            return false;
        }
        let (jobs, job_rx) = sync_channel::<Job>(IN_FLIGHT);
        let (reply_tx, replies) = sync_channel::<Result<u64, Error>>(1);
        let failed = Arc::new(AtomicBool::new(false));
        let flag = failed.clone();
        let width = self.width;
        // The thread is started before the file is handed over (its first job): a spawn
        // that fails leaves the file here, formatted in place.
        let spawned = std::thread::Builder::new()
            .name("pdyn-table-writer".into())
            .spawn(move || {
                let Ok(Job::File(mut file)) = job_rx.recv() else {
                    return None;
                };
                write_batches(&mut file, job_rx, &reply_tx, &flag, width);
                Some(file)
            });
        let Ok(thread) = spawned else {
            return false;
        };
        let State::Inline(file) = std::mem::replace(&mut self.state, State::Lost) else {
            return false;
        };
        if let Err(returned) = jobs.send(Job::File(file)) {
            // The thread ended before its first job (cannot happen): the file stays here.
            if let Job::File(file) = returned.0 {
                self.state = State::Inline(file);
            }
            return false;
        }
        self.state = State::Writer(Writer {
            jobs,
            replies,
            failed,
            thread,
        });
        true
    }

    /// The writer stopped taking jobs: its thread ended. Joins it for the file back (so that
    /// the error from here on is the lost writer's, not a hang).
    fn writer_ended(&mut self) -> Error {
        if let State::Writer(w) = std::mem::replace(&mut self.state, State::Lost) {
            drop(w.jobs);
            if let Ok(Some(file)) = w.thread.join() {
                self.state = State::Inline(file);
            }
        }
        lost(&self.path)
    }
}

impl Drop for NumberRows {
    /// Stops the writer (rows not flushed are dropped, as a [`RowFile`]'s unflushed buffer).
    fn drop(&mut self) {
        if let State::Writer(w) = std::mem::replace(&mut self.state, State::Lost) {
            drop(w.jobs);
            let _ = w.thread.join();
        }
    }
}

fn lost(path: &std::path::Path) -> Error {
    Error::io(
        path,
        "write",
        std::io::Error::other("the table's writer thread ended unexpectedly"),
    )
}

/// Formats whole rows of `width` numbers into `file`.
fn format_rows(file: &mut RowFile, numbers: &[f64], width: usize) -> Result<(), Error> {
    for row in numbers.chunks(width) {
        file.rows(|out| {
            for (i, &x) in row.iter().enumerate() {
                if i > 0 {
                    out.push(b',');
                }
                crate::output::append_number(out, x);
            }
            out.push(b'\n');
        })?;
    }
    Ok(())
}

/// The writer thread: batches in order until the sender is dropped. After the first error,
/// batches are dropped unwritten and every flush replies with that error.
fn write_batches(
    file: &mut RowFile,
    jobs: Receiver<Job>,
    replies: &SyncSender<Result<u64, Error>>,
    failed: &AtomicBool,
    width: usize,
) {
    let mut error: Option<Error> = None;
    for job in jobs {
        match job {
            // Only ever the first job, taken before this loop.
            Job::File(_) => {}
            Job::Rows(batch) => {
                if error.is_none() {
                    if let Err(e) = format_rows(file, &batch, width) {
                        error = Some(e);
                        failed.store(true, Ordering::Relaxed);
                    }
                }
            }
            Job::Flush(sync) => {
                let reply = match &error {
                    Some(e) => Err(e.clone()),
                    None => {
                        let done = if sync { file.sync() } else { file.flush() };
                        done.map(|()| file.len())
                    }
                };
                if replies.send(reply).is_err() {
                    return;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{NumberRows, BATCH};
    use crate::stream::RowFile;

    fn rows(n: usize, width: usize) -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| {
                (0..width)
                    .map(|j| i as f64 * 0.1 + j as f64 / 3.0)
                    .collect()
            })
            .collect()
    }

    /// The bytes formatted in place, for comparison.
    fn expected(header: &str, rows: &[Vec<f64>]) -> Vec<u8> {
        let mut out = header.as_bytes().to_vec();
        for r in rows {
            for (i, &x) in r.iter().enumerate() {
                if i > 0 {
                    out.push(b',');
                }
                crate::output::append_number(&mut out, x);
            }
            out.push(b'\n');
        }
        out
    }

    /// A table of many batches goes to the writer thread (on a machine with two cores) and
    /// comes out with the bytes of in-place formatting; the length `sync` reports is the
    /// file's, mid-run and at the end; a small table stays in place.
    #[test]
    fn a_large_table_is_written_by_the_writer_with_the_same_bytes() {
        let dir = std::env::temp_dir().join(format!("pdyn-number-rows-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.csv");
        let width = 37;
        let all = rows(3 * BATCH / width + 11, width);
        let mut table = NumberRows::new(RowFile::create(&path, "h\n").unwrap(), width);
        let half = all.len() / 2;
        for r in &all[..half] {
            table.row(r).unwrap();
        }
        let at = table.sync().unwrap();
        let want_half = expected("h\n", &all[..half]);
        assert_eq!(at, want_half.len() as u64);
        assert_eq!(std::fs::read(&path).unwrap(), want_half);
        for r in &all[half..] {
            table.row(r).unwrap();
        }
        let end = table.flush().unwrap();
        let parallel = std::thread::available_parallelism().map_or(1, |n| n.get());
        assert_eq!(table.on_writer_thread(), parallel > 1);
        drop(table);
        let want = expected("h\n", &all);
        assert_eq!(end, want.len() as u64);
        assert_eq!(std::fs::read(&path).unwrap(), want);

        let small = rows(10, width);
        let mut table = NumberRows::new(RowFile::create(&path, "h\n").unwrap(), width);
        for r in &small {
            table.row(r).unwrap();
        }
        table.flush().unwrap();
        assert!(!table.on_writer_thread());
        drop(table);
        assert_eq!(std::fs::read(&path).unwrap(), expected("h\n", &small));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! Output files written as a run goes (issue 29): whole rows only, in bounded memory.
//!
//! A [`RowFile`] gathers complete rows in a buffer and hands the buffer to the operating system
//! in one `write_all` when it passes [`FLUSH_BYTES`] (and at [`RowFile::flush`]): a buffer never
//! holds part of a row, so a run killed at any instant leaves a file that ends with a whole row
//! (the rows still in the buffer are lost, never cut). [`RowFile::len`] is the file's length
//! after the last flush: a checkpoint records it, and a restart truncates the file back to it
//! before appending ([`RowFile::resume`]), so no row is written twice or lost.

use crate::Error;
use std::fs::{File, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// The buffer is written out when it holds more than this many bytes.
pub const FLUSH_BYTES: usize = 64 * 1024;

/// One output file written row by row.
#[derive(Debug)]
pub struct RowFile {
    path: PathBuf,
    file: File,
    buf: Vec<u8>,
    written: u64,
}

impl RowFile {
    /// Creates (truncates) `path` and writes `header` (a whole line, with its newline).
    pub fn create(path: &Path, header: &str) -> Result<RowFile, Error> {
        let file = File::create(path).map_err(|e| Error::io(path, "create", e))?;
        let mut f = RowFile {
            path: path.to_path_buf(),
            file,
            buf: Vec::with_capacity(FLUSH_BYTES + 4096),
            written: 0,
        };
        f.buf.extend_from_slice(header.as_bytes());
        f.flush()?;
        Ok(f)
    }

    /// Opens `path` to append after its first `len` bytes (what a checkpoint recorded): a
    /// longer file (rows written after the checkpoint) is truncated back to `len`; a shorter
    /// one is refused (rows the checkpoint counts are missing).
    pub fn resume(path: &Path, len: u64) -> Result<RowFile, Error> {
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| Error::io(path, "open for appending", e))?;
        let have = file
            .metadata()
            .map_err(|e| Error::io(path, "read the length of", e))?
            .len();
        if have < len {
            return Err(Error::io(
                path,
                "resume",
                std::io::Error::other(format!(
                    "the file has {have} bytes, fewer than the {len} the checkpoint recorded: rows are missing"
                )),
            ));
        }
        file.set_len(len)
            .map_err(|e| Error::io(path, "truncate", e))?;
        file.seek(SeekFrom::Start(len))
            .map_err(|e| Error::io(path, "seek in", e))?;
        Ok(RowFile {
            path: path.to_path_buf(),
            file,
            buf: Vec::with_capacity(FLUSH_BYTES + 4096),
            written: len,
        })
    }

    /// Appends whole rows: `f` writes one or more complete lines into the buffer.
    pub fn rows(&mut self, f: impl FnOnce(&mut Vec<u8>)) -> Result<(), Error> {
        f(&mut self.buf);
        if self.buf.len() >= FLUSH_BYTES {
            self.flush()?;
        }
        Ok(())
    }

    /// Hands the buffered rows to the operating system. A write that fails part-way (a full
    /// disk, a file-size limit) is undone: the file is cut back to its length after the last
    /// flush, so it still ends with a whole row, and the error says so.
    pub fn flush(&mut self) -> Result<(), Error> {
        if self.buf.is_empty() {
            return Ok(());
        }
        if let Err(e) = self.file.write_all(&self.buf) {
            let cut = self
                .file
                .set_len(self.written)
                .and_then(|()| self.file.seek(SeekFrom::Start(self.written)));
            let kept = match cut {
                Ok(_) => format!(
                    "{e}; the file was cut back to its last whole row ({} bytes)",
                    self.written
                ),
                Err(c) => format!(
                    "{e}; cutting the file back to its last whole row ({} bytes) failed too ({c}): its last line may be partial",
                    self.written
                ),
            };
            return Err(Error::io(
                &self.path,
                "write",
                std::io::Error::new(e.kind(), kept),
            ));
        }
        self.written += self.buf.len() as u64;
        self.buf.clear();
        Ok(())
    }

    /// Flushed and forced to the disk (before a checkpoint names its length).
    pub fn sync(&mut self) -> Result<(), Error> {
        self.flush()?;
        self.file
            .sync_data()
            .map_err(|e| Error::io(&self.path, "sync", e))
    }

    /// Bytes in the file after the last flush.
    pub fn len(&self) -> u64 {
        self.written
    }

    /// Whether nothing was written (not even a header).
    pub fn is_empty(&self) -> bool {
        self.written == 0
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_written_whole_and_resume_truncates_to_the_recorded_length() {
        let dir = std::env::temp_dir().join(format!("pdyn-stream-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.csv");
        let mut f = RowFile::create(&path, "x\n").unwrap();
        f.rows(|b| b.extend_from_slice(b"1\n")).unwrap();
        f.flush().unwrap();
        let at = f.len();
        f.rows(|b| b.extend_from_slice(b"2\n")).unwrap();
        f.flush().unwrap();
        drop(f);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "x\n1\n2\n");
        let mut f = RowFile::resume(&path, at).unwrap();
        f.rows(|b| b.extend_from_slice(b"3\n")).unwrap();
        f.flush().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "x\n1\n3\n");
        assert!(RowFile::resume(&path, 100).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! Transfer functions on a large grid written while they are computed, block of frequencies
//! by block (`tiltnoise tf` on up to 10^8 points): the layouts of [`crate::write_tf_hdf5`]
//! (the frequency and transfer datasets chunked and growing) and [`crate::write_tf_csv`] (the
//! same text, line by line). Atomic as every output: the data go to a staging directory
//! ([`AtomicFile`]) handed to the run's [`Staging`] by `finish`, removed if the writer is
//! dropped before (a failed or interrupted run).

use super::h5util::str_attr;
use super::tf_csv::{push_tf_csv_rows, tf_csv_header};
use super::tf_hdf5::{transfer_attrs, write_labels, write_modes, write_root};
use crate::atomic::{AtomicFile, Staging};
use crate::run_meta::RunMeta;
use ndarray::{s, ArrayView1, ArrayView3};
use num_complex::Complex64;
use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::tf::TransferMatrix;

/// Frequencies per HDF5 chunk of `/frequency_hz`, and complex values (about) per chunk of
/// `/transfer` (64 KiB).
pub const TF_CHUNK_FREQS: usize = 4096;

fn h5_error(e: hdf5::Error) -> String {
    format!("HDF5: {}", crate::messages::first_line(&e.to_string()))
}

/// A `tiltnoise.tf` HDF5 file being written block by block.
pub struct TfHdf5Writer {
    out: AtomicFile,
    file: hdf5::File,
    meta: RunMeta,
    /// `/frequency_hz` and `/transfer`, created with the first block (which gives the labels).
    data: Option<(hdf5::Dataset, hdf5::Dataset)>,
    len: usize,
}

impl std::fmt::Debug for TfHdf5Writer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TfHdf5Writer")
            .field("target", &self.out.target())
            .field("len", &self.len)
            .finish_non_exhaustive()
    }
}

impl TfHdf5Writer {
    /// Creates the file of `path` in its staging directory; the run's provenance `meta` is stored with it.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming `path`; nothing is left there.
    pub fn create(path: &Path, meta: &RunMeta) -> Result<TfHdf5Writer, OutputError> {
        let out = AtomicFile::create(path)?;
        let file = hdf5::File::create(out.temp_path()).map_err(|e| out.fail(h5_error(e)))?;
        Ok(TfHdf5Writer {
            out,
            file,
            meta: meta.clone(),
            data: None,
            len: 0,
        })
    }

    /// Appends the next block of the grid. Every block must have the labels and method of the
    /// first.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target.
    pub fn append(&mut self, block: &TransferMatrix) -> Result<(), OutputError> {
        let written = (|| -> hdf5::Result<()> {
            let (nf, no, ni) = (
                block.freqs_hz.len(),
                block.outputs.len(),
                block.inputs.len(),
            );
            if block.n_stored_freqs() != nf {
                return Err(format!(
                    "transfer matrix holds values at {} frequencies, expected {nf}",
                    block.n_stored_freqs()
                )
                .into());
            }
            if self.data.is_none() {
                write_root(&self.file, block, &self.meta)?;
                let freq = self
                    .file
                    .new_dataset::<f64>()
                    .chunk(TF_CHUNK_FREQS)
                    .shape(0..)
                    .create("frequency_hz")?;
                str_attr(&freq, "unit", "Hz")?;
                let transfer = self
                    .file
                    .new_dataset::<Complex64>()
                    .chunk((TF_CHUNK_FREQS.div_ceil(no * ni).max(1), no, ni))
                    .shape((0.., no, ni))
                    .create("transfer")?;
                transfer_attrs(&transfer, block)?;
                write_labels(&self.file, block)?;
                self.data = Some((freq, transfer));
            }
            let (freq, transfer) = self.data.as_ref().expect("created above");
            let shape = transfer.shape();
            if shape[1..] != [no, ni] {
                return Err(format!(
                    "a block of {no} x {ni} transfer functions after blocks of {} x {}",
                    shape[1], shape[2]
                )
                .into());
            }
            let (start, end) = (self.len, self.len + nf);
            freq.resize(end)?;
            freq.write_slice(ArrayView1::from(&block.freqs_hz), s![start..end])?;
            let dense = block.dense_values();
            let values = ArrayView3::from_shape((nf, no, ni), &dense).map_err(|e| e.to_string())?;
            transfer.resize((end, no, ni))?;
            transfer.write_slice(values, s![start..end, .., ..])?;
            Ok(())
        })();
        written.map_err(|e| self.out.fail(h5_error(e)))?;
        self.len += block.freqs_hz.len();
        Ok(())
    }

    /// Writes the modes, closes the file and hands it to `stage`, which renames it onto the
    /// target when it commits.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target (also when no block was appended); nothing is
    /// left there.
    pub fn finish(self, stage: &Staging) -> Result<(), OutputError> {
        let TfHdf5Writer {
            out,
            file,
            meta,
            data,
            ..
        } = self;
        if data.is_none() {
            return Err(out.fail("no frequency was written".to_string()));
        }
        drop(data);
        write_modes(&file, &meta)
            .and_then(|()| file.close())
            .map_err(|e| out.fail(h5_error(e)))?;
        out.finish(stage)
    }
}

/// A transfer-function CSV file being written block by block: the same text as
/// [`crate::write_tf_csv`] of the whole grid.
pub struct TfCsvWriter {
    out: AtomicFile,
    meta: RunMeta,
    writer: BufWriter<File>,
    header: Option<String>,
    text: String,
}

impl std::fmt::Debug for TfCsvWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TfCsvWriter")
            .field("target", &self.out.target())
            .finish_non_exhaustive()
    }
}

impl TfCsvWriter {
    /// Creates the file of `path` in its staging directory.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming `path`; nothing is left there.
    pub fn create(path: &Path, meta: &RunMeta) -> Result<TfCsvWriter, OutputError> {
        let out = AtomicFile::create(path)?;
        let file = File::create(out.temp_path()).map_err(|e| out.fail(e.to_string()))?;
        Ok(TfCsvWriter {
            out,
            meta: meta.clone(),
            writer: BufWriter::with_capacity(1 << 20, file),
            header: None,
            text: String::new(),
        })
    }

    /// Appends the lines of the next block of the grid (after the header line, with the first
    /// block). Every block must have the labels of the first.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target.
    pub fn append(&mut self, block: &TransferMatrix) -> Result<(), OutputError> {
        let header = tf_csv_header(block, &self.meta);
        self.text.clear();
        match &self.header {
            None => self.text.push_str(&header),
            Some(h) if *h != header => {
                return Err(self.out.fail(format!(
                    "a block with the columns {} after blocks with {}",
                    header.trim_end(),
                    h.trim_end()
                )))
            }
            Some(_) => {}
        }
        push_tf_csv_rows(&mut self.text, block);
        self.writer
            .write_all(self.text.as_bytes())
            .map_err(|e| self.out.fail(e.to_string()))?;
        self.header = Some(header);
        Ok(())
    }

    /// Flushes and closes the file and hands it to `stage`, which renames it onto the target
    /// when it commits.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target (also when no block was appended); nothing is
    /// left there.
    pub fn finish(self, stage: &Staging) -> Result<(), OutputError> {
        let TfCsvWriter {
            out,
            writer,
            header,
            ..
        } = self;
        if header.is_none() {
            return Err(out.fail("no frequency was written".to_string()));
        }
        let file = writer
            .into_inner()
            .map_err(|e| out.fail(e.error().to_string()))?;
        drop(file);
        out.finish(stage)
    }
}

//! A simulated record written to HDF5 while it is computed (`tiltnoise simulate`), in the
//! layout of [`crate::write_observable_series_hdf5`] (schema `tiltnoise.observable_series`):
//! the series are chunked datasets that grow with each chunk appended, the ASDs and the other
//! groups are written when the record is complete. Atomic as every output: the data go to a
//! staging directory ([`AtomicFile`]) handed to the run's [`Staging`] by
//! [`ObservableSeriesWriter::finish`], removed if the writer is dropped before (a failed or
//! interrupted run).

use super::h5util::str_attr;
use super::series_hdf5::{check_asd, series_attrs, write_groups, write_root};
use crate::atomic::{AtomicFile, Staging};
use crate::series_hdf5::{SeriesAsd, SimulationMeta};
use ndarray::{s, ArrayView1};
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::model::{Coord, Observable};
use tiltnoise_core::simulate::stream::SimChunk;

/// Samples per HDF5 chunk of a series dataset (512 KiB of `f64`): large enough for fast
/// sequential reads, small enough that reading a few samples costs little.
pub const SERIES_CHUNK_SAMPLES: usize = 1 << 16;

/// Name of the group holding the generalized coordinates, when they are kept.
pub const COORDINATES_GROUP: &str = "coordinates";

/// An observable-series HDF5 file being written chunk by chunk.
pub struct ObservableSeriesWriter {
    out: AtomicFile,
    file: hdf5::File,
    series: Vec<hdf5::Dataset>,
    coordinates: Vec<hdf5::Dataset>,
    len: usize,
    meta: SimulationMeta,
}

impl std::fmt::Debug for ObservableSeriesWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObservableSeriesWriter")
            .field("target", &self.out.target())
            .field("len", &self.len)
            .finish_non_exhaustive()
    }
}

fn h5_error(e: hdf5::Error) -> String {
    format!("HDF5: {}", crate::messages::first_line(&e.to_string()))
}

/// A 1-D float64 dataset of length 0 that grows by [`ObservableSeriesWriter::append`].
fn growing(group: &hdf5::Group, name: &str) -> hdf5::Result<hdf5::Dataset> {
    group
        .new_dataset::<f64>()
        .chunk(SERIES_CHUNK_SAMPLES)
        .shape(0..)
        .create(name)
}

fn append_to(ds: &hdf5::Dataset, start: usize, values: &[f64]) -> hdf5::Result<()> {
    let end = start + values.len();
    ds.resize(end)?;
    ds.write_slice(ArrayView1::from(values), s![start..end])
}

impl ObservableSeriesWriter {
    /// Creates the file of `path`, in its staging directory, with the root attributes of a series of step
    /// `dt_s` (s) and empty series of the seven observables, plus the eight generalized
    /// coordinates (group `/coordinates`, noiseless) when `with_coordinates`.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming `path`; nothing is left there.
    pub fn create(
        path: &Path,
        dt_s: f64,
        meta: &SimulationMeta,
        with_coordinates: bool,
    ) -> Result<ObservableSeriesWriter, OutputError> {
        let out = AtomicFile::create(path)?;
        let opened = (|| -> hdf5::Result<_> {
            let file = hdf5::File::create(out.temp_path())?;
            write_root(&file, dt_s, meta)?;
            let mut series = Vec::with_capacity(7);
            for o in Observable::ALL {
                let ds = growing(&file, o.name())?;
                series_attrs(&ds, o, meta)?;
                series.push(ds);
            }
            let mut coordinates = Vec::new();
            if with_coordinates {
                let g = file.create_group(COORDINATES_GROUP)?;
                str_attr(
                    &g,
                    "description",
                    "generalized coordinates of the simulated motion, without readout noise",
                )?;
                for c in Coord::ALL {
                    let ds = growing(&g, c.name())?;
                    str_attr(&ds, "unit", c.unit())?;
                    coordinates.push(ds);
                }
            }
            Ok((file, series, coordinates))
        })();
        let (file, series, coordinates) = opened.map_err(|e| out.fail(h5_error(e)))?;
        Ok(ObservableSeriesWriter {
            out,
            file,
            series,
            coordinates,
            len: 0,
            meta: meta.clone(),
        })
    }

    /// Samples written so far.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True before the first sample.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Appends the next chunk of the record: it must start where the last one ended, and hold
    /// the coordinates if the file keeps them.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target on an HDF5 failure or a chunk out of place.
    pub fn append(&mut self, chunk: &SimChunk) -> Result<(), OutputError> {
        if chunk.start != self.len {
            return Err(self.out.fail(format!(
                "chunk starts at sample {} but {} samples are written",
                chunk.start, self.len
            )));
        }
        if !self.coordinates.is_empty() && chunk.q.len() != chunk.len() {
            return Err(self.out.fail(format!(
                "chunk at sample {} holds {} coordinate samples for {} observable samples",
                chunk.start,
                chunk.q.len(),
                chunk.len()
            )));
        }
        let written = (|| -> hdf5::Result<()> {
            for (ds, values) in self.series.iter().zip(&chunk.observables) {
                append_to(ds, self.len, values)?;
            }
            let mut column = Vec::with_capacity(chunk.q.len());
            for (i, ds) in self.coordinates.iter().enumerate() {
                column.clear();
                column.extend(chunk.q.iter().map(|q| q[i]));
                append_to(ds, self.len, &column)?;
            }
            Ok(())
        })();
        written.map_err(|e| self.out.fail(h5_error(e)))?;
        self.len += chunk.len();
        Ok(())
    }

    /// Writes the ASDs and the other groups, closes the file and hands it to `stage`, which
    /// renames it onto the target when it commits.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target; nothing is left there.
    pub fn finish(self, stage: &Staging, asd: &SeriesAsd) -> Result<(), OutputError> {
        let ObservableSeriesWriter {
            out,
            file,
            series,
            coordinates,
            meta,
            ..
        } = self;
        check_asd(asd).map_err(|m| out.fail(m))?;
        drop((series, coordinates));
        write_groups(&file, asd, &meta)
            .and_then(|()| file.close())
            .map_err(|e| out.fail(h5_error(e)))?;
        out.finish(stage)
    }
}

//! The transfer-function job: inputs and observables, a frequency grid (the default one, a
//! log grid computed point by point, given points or a file of them), the floor's motion per
//! unit displacement, velocity or acceleration, and a method (or `auto`, the planner's pick)
//! to the transfer matrix, whole or block by block in memory that does not grow with the grid.

mod outcome;
mod stream;

pub use outcome::{TfOutcome, OUTPUT_KINDS};
pub use stream::TfText;

use crate::error::{shown_path, JobError};
use crate::figures::TfFigureOptions;
use crate::outcome::{Invocation, Provenance};
use crate::progress::Progress;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::freq::{self, LogGrid};
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::limits::MAX_GRID_POINTS;
use tiltnoise_core::model::Observable;
use tiltnoise_core::model::{Model, Request};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::tf::planner::{Choice, Scene, DEFAULT_REL_TOL};
use tiltnoise_core::tf::{self, Method, TransferFunction, TransferMatrix};
use tiltnoise_io::read_freq_file;

/// Frequencies per block of a streamed grid: 16384 points of the largest request (7 x 15
/// complex values) are 27 MB with the CSV text of the block.
pub const DEFAULT_BLOCK_FREQS: usize = 1 << 14;

/// The frequencies to evaluate (Hz).
#[derive(Debug, Clone)]
pub enum FreqGrid {
    /// The default grid ([`freq::default_grid`]): 0.1 mHz to 30 Hz plus points around every
    /// resonance.
    Default,
    /// A log grid, computed point by point (it may hold more points than fit in memory).
    Log(LogGrid),
    /// Given frequencies.
    Points(Vec<f64>),
    /// A file of frequencies, one per line.
    File(PathBuf),
}

/// Transfer functions to evaluate.
pub struct TfRequest<'a> {
    /// The model.
    pub model: &'a Model,
    /// Inputs (columns) and observables (rows).
    pub request: Request,
    /// The frequencies.
    pub grid: FreqGrid,
    /// The floor's motion per unit displacement (the model's inputs), velocity or
    /// acceleration; forces and torques stay per N and N m.
    pub per: GroundQuantity,
    /// The method (`None`: `auto`, the planner's pick).
    pub method: Option<Method>,
    /// The tolerance of `auto`, a relative error in (0, 1) (default
    /// [`DEFAULT_REL_TOL`]).
    pub rel_tol: Option<f64>,
    /// Frequencies evaluated per block when streamed (default [`DEFAULT_BLOCK_FREQS`]).
    pub block_freqs: Option<usize>,
    /// A figure the whole matrix is drawn into: the grid must then fit in memory.
    pub figure: Option<PathBuf>,
    /// The figures' panels, phase, limits and view ([`figure_options`]).
    pub figure_options: TfFigureOptions,
    /// Who asked, for the provenance.
    pub invocation: Invocation,
}

impl TfRequest<'_> {
    /// The files the job reads, each with the option (snake case) that names it.
    pub fn input_files(&self) -> Vec<(&'static str, &std::path::Path)> {
        match &self.grid {
            FreqGrid::File(path) => vec![("freq_file", path.as_path())],
            _ => Vec::new(),
        }
    }
}

/// A grid held in memory or computed point by point.
enum Grid {
    Points(Vec<f64>),
    Log(LogGrid),
}

impl Grid {
    fn len(&self) -> usize {
        match self {
            Grid::Points(v) => v.len(),
            Grid::Log(g) => g.len(),
        }
    }

    fn block(&self, start: usize, len: usize) -> Vec<f64> {
        match self {
            Grid::Points(v) => {
                let end = start.saturating_add(len).min(v.len());
                v[start.min(end)..end].to_vec()
            }
            Grid::Log(g) => g.block(start, len),
        }
    }

    fn band(&self) -> (f64, f64) {
        match self {
            Grid::Log(g) => (g.lo_hz(), g.hi_hz()),
            Grid::Points(freqs) => positive_band(freqs),
        }
    }
}

/// The band `auto` plans for: that of the positive finite frequencies, or the default lowest
/// frequency when there is none.
pub fn positive_band(freqs: &[f64]) -> (f64, f64) {
    let positive = freqs.iter().copied().filter(|&f| f > 0.0 && f.is_finite());
    let lo = positive.clone().fold(f64::INFINITY, f64::min);
    let hi = positive.fold(0.0, f64::max);
    match hi > 0.0 {
        true => (lo, hi),
        false => (freq::DEFAULT_F_LO_HZ, freq::DEFAULT_F_LO_HZ),
    }
}

/// `rel_tol` checked: a finite relative error in (0, 1) (default [`DEFAULT_REL_TOL`]).
///
/// # Errors
///
/// [`JobError::Option`] naming `rel_tol`.
pub fn rel_tol(rel_tol: Option<f64>) -> Result<f64, JobError> {
    match rel_tol {
        None => Ok(DEFAULT_REL_TOL),
        Some(r) if r.is_finite() && r > 0.0 && r < 1.0 => Ok(r),
        Some(r) => Err(JobError::option(
            OptionKey::REL_TOL,
            Some(&r.to_string()),
            "the tolerance must be a finite relative error in (0, 1)".to_string(),
        )),
    }
}

/// The planner's pick for `request` on `band_hz` at `rel_tol`, with its evidence.
///
/// # Errors
///
/// [`JobError::NoMethod`] when no method can be checked or none meets the tolerance.
pub fn choose(
    model: &Model,
    request: &Request,
    band_hz: (f64, f64),
    rel_tol: f64,
) -> Result<Choice, JobError> {
    let scene = Scene {
        request: request.clone(),
        band_hz,
        rel_tol,
    };
    tf::choose(model, &scene).map_err(|e| JobError::NoMethod(Box::new(e)))
}

/// The plan of `request` with `method` (its per-model work done once).
///
/// # Errors
///
/// [`JobError::Plan`] for a method that cannot evaluate the request on this model.
pub fn plan(
    model: &Model,
    request: &Request,
    method: Method,
) -> Result<Box<dyn TransferFunction>, JobError> {
    tf::plan(model, request, method).map_err(|e| JobError::Plan(Box::new(e)))
}

/// A planned job: the grid read and checked, the method chosen and its plan built.
pub struct Planned {
    plan: Box<dyn TransferFunction>,
    /// The exact form of the floor's columns where `w^2` leaves the range of `f64`.
    low: tf::LowFrequency,
    grid: Grid,
    per: GroundQuantity,
    block_freqs: usize,
    /// `auto`'s pick with every candidate's measured error (`None` for a method asked for).
    pub choice: Option<Choice>,
    provenance: Provenance,
    figure: TfFigureOptions,
}

impl Planned {
    /// The request evaluated.
    pub fn request(&self) -> &Request {
        self.plan.request()
    }

    /// The method evaluated.
    pub fn method(&self) -> Method {
        self.plan.method()
    }

    /// Frequencies of the grid.
    pub fn len(&self) -> usize {
        self.grid.len()
    }

    /// Whether the grid is empty.
    pub fn is_empty(&self) -> bool {
        self.grid.len() == 0
    }

    /// The transfer matrix on `freqs_hz`, per unit of the requested quantity.
    fn evaluate(&self, freqs_hz: &[f64], cancel: &Cancel) -> Result<TransferMatrix, JobError> {
        cancel.check().map_err(|e| tf_error(e.into()))?;
        let m = tf::evaluate(self.plan.as_ref(), freqs_hz).map_err(tf_error)?;
        match self.per {
            GroundQuantity::Displacement if !self.low.applies_to(freqs_hz) => Ok(m),
            per => m.per_ground_quantity(per, &self.low).map_err(tf_error),
        }
    }

    /// The provenance every output of the run records.
    pub fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// The whole grid at once.
    ///
    /// # Errors
    ///
    /// [`JobError::Tf`] at the first frequency without a value, or when cancelled.
    pub fn whole(&self, cancel: &Cancel) -> Result<TransferMatrix, JobError> {
        self.evaluate(&self.grid.block(0, self.grid.len()), cancel)
    }

    /// The outcome of the whole grid at once, to save by output kind.
    ///
    /// # Errors
    ///
    /// As [`Planned::whole`].
    pub fn outcome(&self, cancel: &Cancel, progress: &dyn Progress) -> Result<TfOutcome, JobError> {
        let tf = self.whole(cancel);
        progress.finish();
        Ok(TfOutcome {
            tf: tf?,
            choice: self.choice.clone(),
            provenance: self.provenance.clone(),
            figure: self.figure.clone(),
        })
    }

    /// The grid block by block, each handed to `sink` with the number of frequencies done
    /// (that block's included) before the next is computed. The values do not depend on the
    /// block size.
    ///
    /// # Errors
    ///
    /// The first error of `sink`, or [`JobError::Tf`] as [`Planned::whole`].
    pub fn blocks<E: From<JobError>>(
        &self,
        cancel: &Cancel,
        mut sink: impl FnMut(&TransferMatrix, usize) -> Result<(), E>,
    ) -> Result<(), E> {
        let n = self.grid.len();
        let mut start = 0;
        while start < n {
            let freqs = self.grid.block(start, self.block_freqs);
            let block = self.evaluate(&freqs, cancel)?;
            start += freqs.len();
            sink(&block, start)?;
        }
        Ok(())
    }
}

fn tf_error(e: tiltnoise_core::error::TfError) -> JobError {
    JobError::Tf(Box::new(e))
}

/// Checks the options against the grid, reads a file of frequencies, chooses the method and
/// builds its plan.
///
/// # Errors
///
/// A [`JobError`] naming the option or file that failed; [`JobError::NoMethod`] when `auto`
/// finds none.
pub fn prepare(req: &TfRequest<'_>) -> Result<Planned, JobError> {
    let rel_tol = rel_tol(req.rel_tol)?;
    let block_freqs = match req.block_freqs {
        Some(0) => {
            return Err(JobError::option(
                OptionKey::BLOCK_FREQS,
                Some("0"),
                "a block must hold at least 1 frequency".to_string(),
            ))
        }
        Some(b) => b,
        None => DEFAULT_BLOCK_FREQS,
    };
    let (grid, origin) = match req.grid.clone() {
        FreqGrid::Default => (Grid::Points(freq::default_grid(req.model)), None),
        FreqGrid::Log(g) => (Grid::Log(g), None),
        FreqGrid::Points(v) => (Grid::Points(v), Some((OptionKey::FREQ_HZ, None))),
        FreqGrid::File(path) => {
            let freqs = read_freq_file(&path).map_err(|e| JobError::Freq(Box::new(e)))?;
            (
                Grid::Points(freqs),
                Some((OptionKey::FREQ_FILE, Some(shown_path(&path)))),
            )
        }
    };
    if let (Grid::Points(freqs), Some((option, file))) = (&grid, &origin) {
        refuse_zero_for_per(freqs, req.per, &req.request, *option, file.as_deref())?;
    }
    if let (Some(path), Grid::Log(g)) = (&req.figure, &grid) {
        if g.len() > MAX_GRID_POINTS {
            return Err(JobError::option(
                OptionKey::SAVE,
                Some(&shown_path(path)),
                tiltnoise_core::message!(
                    "a figure is drawn from at most {MAX_GRID_POINTS} frequency points and {} \
                     asks for {}; draw it from a smaller grid (the default grid resolves every \
                     resonance) and write the large one to .h5 or .csv only (see \
                     docs/limits.md)",
                    OptionKey::FREQ_HZ,
                    g.len()
                ),
            ));
        }
    }
    let (method, choice) = match req.method {
        Some(m) => (m, None),
        None => {
            let choice = choose(req.model, &req.request, grid.band(), rel_tol)?;
            (choice.method, Some(choice))
        }
    };
    Ok(Planned {
        plan: plan(req.model, &req.request, method)?,
        low: tf::LowFrequency::new(req.model, &req.request),
        grid,
        per: req.per,
        block_freqs,
        choice,
        provenance: crate::modes::provenance(req.model, &req.invocation),
        figure: req.figure_options.clone(),
    })
}

/// Refuses 0 Hz in a grid of a request with floor inputs per unit velocity or acceleration,
/// where such a transfer function has no value.
fn refuse_zero_for_per(
    freqs: &[f64],
    per: GroundQuantity,
    request: &Request,
    option: OptionKey,
    file: Option<&str>,
) -> Result<(), JobError> {
    if !request.inputs.iter().any(|i| i.is_ground()) {
        return Ok(());
    }
    let Some(k) = freqs.iter().position(|&f| per.to_displacement(f).is_none()) else {
        return Ok(());
    };
    let q = per.name();
    let at = match file {
        Some(file) => tiltnoise_core::message!("frequency {} of {}", k + 1, file.to_string()),
        None => tiltnoise_core::message!("frequency {} of {}", k + 1, option),
    };
    Err(JobError::option(
        OptionKey::PER,
        Some(q),
        tiltnoise_core::message!(
            "{at} is 0 Hz, where a transfer function per unit floor {q} has no value (a floor {q} \
             carries no displacement at DC); use frequencies above 0 Hz"
        ),
    ))
}

/// Runs the job whole: [`prepare`], then the matrix on the whole grid (to stream a grid
/// larger than memory, [`Planned::stream`]).
///
/// # Errors
///
/// As [`prepare`] and [`Planned::whole`].
pub fn run(
    req: &TfRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<TfOutcome, JobError> {
    prepare(req)?.outcome(cancel, progress)
}

/// The observables a figure draws when none are chosen: those of the paper's Figure 5.
pub const FIGURE5_OBSERVABLES: [Observable; 3] = [Observable::X, Observable::Phi, Observable::PhiA];

/// The figure of a matrix of `model`: a row of panels per observable of `drawn` (each one
/// computed), a phase panel beside each with `phase`, the caption saying whether the model is
/// damped and naming the option that chooses the panels as `panels_option` (the front end's
/// spelling of [`OptionKey::DRAWN_OBSERVABLES`]), in the default view.
pub fn figure_options(
    model: &Model,
    drawn: Vec<Observable>,
    phase: bool,
    panels_option: String,
) -> TfFigureOptions {
    TfFigureOptions {
        observables: Some(drawn),
        phase,
        damped: !model.is_undamped(),
        view: crate::figures::View::default(),
        note: None,
        panels_option,
    }
}

/// Writes a transfer matrix in the format named by the extension of `path`: HDF5 (schema
/// `tiltnoise.tf`, with `meta`), CSV, or the PNG/SVG figure drawn with `figure`, as one of
/// the outputs of `stage`: the one writer by kind behind [`TfOutcome`]'s `save`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`](tiltnoise_core::error::OutputError::UnknownFormat) for another extension (nothing is written), or the writer's
/// [`OutputError::Write`](tiltnoise_core::error::OutputError::Write) naming `path`.
pub fn save(
    stage: &tiltnoise_io::Staging,
    path: &std::path::Path,
    tf: &TransferMatrix,
    meta: &Provenance,
    figure: &TfFigureOptions,
) -> Result<(), tiltnoise_core::error::OutputError> {
    use tiltnoise_io::OutputKind;
    match crate::output_kind(path, OUTPUT_KINDS)? {
        OutputKind::Hdf5 => tiltnoise_io::write_tf_hdf5(stage, path, tf, meta),
        OutputKind::Csv => tiltnoise_io::write_tf_csv(stage, path, tf, meta),
        _ => crate::save_image(stage, path, |format| {
            tiltnoise_plot::tf_figure_with(tf, format, figure)
        }),
    }
}

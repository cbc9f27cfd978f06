//! Evaluation of a plan on a frequency grid: into a caller's dense buffer
//! ([`eval_grid_threads`]), or into a [`TransferMatrix`] in the plan's own [`Layout`](super::Layout)
//! ([`evaluate`], [`evaluate_into`]), on one or more threads.

use super::buffer::zeroed_f64;
use super::{Request, TransferFunction, TransferMatrix};
use crate::cancel::Cancel;
use crate::error::TfError;
use crate::limits::{check_memory, planned_bytes, GRID_BYTES_PER_ENTRY};
use num_complex::Complex64;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Values per frequency of `request`; panics unless `out` holds that many per frequency of
/// `freqs_hz` (the contract of [`TransferFunction::eval_grid_into`]).
pub(crate) fn check_grid_len(request: &Request, freqs_hz: &[f64], out: &[Complex64]) -> usize {
    let block = request.outputs.len() * request.inputs.len();
    assert_eq!(
        out.len(),
        freqs_hz.len() * block,
        "eval_grid_into: output buffer of {} values for {} frequencies x {block} values",
        out.len(),
        freqs_hz.len()
    );
    block
}

/// Evaluates part of a grid into its part of the output (`J`).
type EvalPart<'a, J> = dyn Fn(&[f64], J) -> Result<(), TfError> + Sync + 'a;

/// A part of the grid and its part of the output, until a thread takes them.
type Slot<'f, J> = Mutex<Option<(&'f [f64], J)>>;

/// `eval` on each `(part of the grid, its part of the output)` of `jobs`, on `threads`
/// threads (`std::thread::scope`; one of them the calling thread) that take the parts in grid
/// order, each the next one not yet taken: a thread that starts late or runs slower (a core
/// that was idle, or shared with other work) takes fewer. The error of the first failing part
/// in grid order; no part after it is started once it is known. `cancel` is polled before each
/// part is taken ([`MAX_PART_POINTS`] bounds the work between two polls).
fn on_threads<'f, J: Send>(
    jobs: impl Iterator<Item = (&'f [f64], J)>,
    threads: usize,
    cancel: &Cancel,
    eval: &EvalPart<'_, J>,
) -> Result<(), TfError> {
    let jobs: Vec<Slot<'_, J>> = jobs.map(|j| Mutex::new(Some(j))).collect();
    let next = AtomicUsize::new(0);
    let first_error: Mutex<Option<(usize, TfError)>> = Mutex::new(None);
    let work = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let Some(slot) = jobs.get(k) else { break };
        if lock(&first_error).as_ref().is_some_and(|(bad, _)| *bad < k) {
            break;
        }
        if cancel.is_cancelled() {
            break;
        }
        let (f, o) = lock(slot).take().expect("each part is taken once");
        if let Err(e) = eval(f, o) {
            let mut first = lock(&first_error);
            if first.as_ref().is_none_or(|(bad, _)| k < *bad) {
                *first = Some((k, e));
            }
        }
    };
    let threads = threads.clamp(1, jobs.len().max(1));
    std::thread::scope(|scope| {
        for _ in 1..threads {
            scope.spawn(work);
        }
        work();
    });
    cancel.check()?;
    first_error
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
        .map_or(Ok(()), |(_, e)| Err(e))
}

/// The mutex's value, also after a panic elsewhere (which `std::thread::scope` passes on).
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// How the output of [`eval_grid_threads`] was obtained, which decides how a large one is
/// written (the values are the same).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Destination {
    /// Memory written before (a buffer used again): an output of [`STREAM_MIN_BYTES`] or
    /// more is written with non-temporal stores, which do not first read each cache line
    /// from memory and do not evict the cache.
    Reused,
    /// Memory just allocated and not yet touched (a new NumPy array): the operating system
    /// zeroes each page at its first touch, which leaves the page in the cache, so ordinary
    /// stores write into the cache where non-temporal ones would first evict it.
    Fresh,
    /// A part of a [`Destination::Reused`] output of [`STREAM_MIN_BYTES`] or more (what
    /// [`eval_grid_threads`] hands each thread): non-temporal stores whatever the part's size.
    Streamed,
}

impl Destination {
    /// Whether an output of `bytes` obtained this way is written with non-temporal stores.
    pub fn streams(self, bytes: usize) -> bool {
        match self {
            Destination::Reused => bytes >= STREAM_MIN_BYTES,
            Destination::Fresh => false,
            Destination::Streamed => true,
        }
    }
}

/// Reused outputs of at least this many bytes are written with non-temporal stores: well
/// above a core's L2 (1 to 2 MiB), about where the output stops fitting in a typical L3 next
/// to other work. Below it, ordinary stores leave the output in the cache for the caller.
pub const STREAM_MIN_BYTES: usize = 8 << 20;

/// Grid points per part handed to a thread: `threads` (0 means 1) each take about
/// [`PARTS_PER_THREAD`] parts of at least [`MIN_PART_POINTS`] points (one part per thread if
/// that leaves fewer), at least one point each, at most [`MAX_PART_POINTS`].
fn part_len(n_freqs: usize, threads: usize) -> usize {
    let threads = threads.max(1);
    if threads == 1 {
        return n_freqs.clamp(1, MAX_PART_POINTS);
    }
    let even = n_freqs.div_ceil(threads);
    n_freqs
        .div_ceil(threads * PARTS_PER_THREAD)
        .max(MIN_PART_POINTS)
        .min(even)
        .clamp(1, MAX_PART_POINTS)
}

/// Largest part of a grid: bounds the work between two polls of the cancellation token
/// (`benches/cancel.rs` measures what it takes to stop), while the start of a part stays
/// negligible against it.
const MAX_PART_POINTS: usize = 1 << 14;

/// Parts per thread of a grid evaluated on several threads: enough that a thread which
/// starts late or runs slower hands its share to the others.
const PARTS_PER_THREAD: usize = 8;

/// Smallest part of a grid handed to a thread: a part costs a few microseconds to start
/// (a chunk buffer, the dispatch), small against the work of 2048 points even with the
/// cheapest method (`benches/methods.rs`).
const MIN_PART_POINTS: usize = 2048;

/// [`TransferFunction::eval_grid_into`] (dense `[freq][output][input]` complex values) with
/// the grid cut into contiguous parts (about eight per thread on a long grid) that `threads`
/// threads take in turn, so that a thread which starts late or runs slower takes fewer. The
/// values do not depend on `threads` (every point is evaluated independently) and are all
/// finite; the error is the one of the first failing frequency in grid order, as with one
/// thread ([`TfError::NotFinite`] for a value that overflowed). `threads = 0` means 1.
/// `destination`: how `out` was obtained ([`Destination`]); the whole output decides how it
/// is written ([`Destination::streams`]).
///
/// # Panics
///
/// If `out` has the wrong length.
pub fn eval_grid_threads(
    tf: &dyn TransferFunction,
    freqs_hz: &[f64],
    out: &mut [Complex64],
    threads: usize,
    destination: Destination,
) -> Result<(), TfError> {
    eval_grid_threads_cancellable(tf, freqs_hz, out, threads, destination, &Cancel::never())
}

/// [`eval_grid_threads`] polling `cancel` between the parts of the grid:
/// [`TfError::Cancelled`] once it is set, the output then holding unspecified values.
///
/// # Panics
///
/// If `out` has the wrong length.
pub fn eval_grid_threads_cancellable(
    tf: &dyn TransferFunction,
    freqs_hz: &[f64],
    out: &mut [Complex64],
    threads: usize,
    destination: Destination,
    cancel: &Cancel,
) -> Result<(), TfError> {
    let block = check_grid_len(tf.request(), freqs_hz, out);
    if block == 0 || freqs_hz.is_empty() {
        return tf.eval_grid_into_dest(freqs_hz, out, destination);
    }
    // The whole output decides how it is written, not each part's size.
    let destination = match destination.streams(std::mem::size_of_val(out)) {
        true => Destination::Streamed,
        false => destination,
    };
    let part = part_len(freqs_hz.len(), threads);
    let jobs = freqs_hz.chunks(part).zip(out.chunks_mut(part * block));
    // `eval_grid_into` checks that every value is finite (while it is in cache).
    on_threads(jobs, threads, cancel, &|f, o| {
        tf.eval_grid_into_dest(f, o, destination)
    })
}

/// Evaluates a plan on every frequency of a grid, on one thread, into a new matrix in the
/// plan's [`Layout`](super::Layout) ([`TransferFunction::layout`]). Stops at the first singular frequency.
///
/// # Errors
///
/// [`TfError::TooLarge`] before allocating when the result and an output written from it
/// ([`GRID_BYTES_PER_ENTRY`] per entry and frequency) do not fit into the memory available;
/// [`TfError::Singular`], [`TfError::NotFinite`] at the first frequency that has no value.
pub fn evaluate(tf: &dyn TransferFunction, freqs_hz: &[f64]) -> Result<TransferMatrix, TfError> {
    let layout = tf.layout();
    let r = tf.request();
    let (n_out, n_in, n) = (r.outputs.len(), r.inputs.len(), freqs_hz.len());
    let entries = (n_out * n_in) as u64;
    check_memory(
        || format!("transfer functions of {n_out} outputs x {n_in} inputs at {n} frequencies"),
        planned_bytes(n, entries.saturating_mul(GRID_BYTES_PER_ENTRY)),
    )?;
    let data = zeroed_f64(layout.n_planes() * n);
    let mut m = TransferMatrix::from_parts(
        Vec::new(),
        r.outputs.clone(),
        r.inputs.clone(),
        tf.method(),
        layout,
        data,
    );
    evaluate_into(tf, freqs_hz, 1, &mut m)?;
    Ok(m)
}

/// [`evaluate`] into an existing matrix, on `threads` threads (0 means 1): its grid, labels,
/// method and values are replaced, its allocations reused when large enough (no page is
/// touched for the first time when `out` held a grid at least this large). The values do not
/// depend on `threads`. On error `out` holds the new labels and unspecified values.
pub fn evaluate_into(
    tf: &dyn TransferFunction,
    freqs_hz: &[f64],
    threads: usize,
    out: &mut TransferMatrix,
) -> Result<(), TfError> {
    evaluate_into_cancellable(tf, freqs_hz, threads, out, &Cancel::never())
}

/// [`evaluate_into`] polling `cancel` between the parts of the grid: [`TfError::Cancelled`]
/// once it is set, `out` then holding unspecified values.
pub fn evaluate_into_cancellable(
    tf: &dyn TransferFunction,
    freqs_hz: &[f64],
    threads: usize,
    out: &mut TransferMatrix,
    cancel: &Cancel,
) -> Result<(), TfError> {
    let r = tf.request();
    out.freqs_hz.clear();
    out.freqs_hz.extend_from_slice(freqs_hz);
    out.outputs.clone_from(&r.outputs);
    out.inputs.clone_from(&r.inputs);
    out.method = tf.method();
    let (layout, data) = out.parts_mut();
    *layout = tf.layout();
    let (n_planes, nf) = (layout.n_planes(), freqs_hz.len());
    let len = n_planes * nf;
    if data.capacity() < len {
        *data = zeroed_f64(len);
    } else {
        data.resize(len, 0.0);
    }
    if nf == 0 {
        return Ok(());
    }
    if n_planes == 0 {
        // Nothing to write; each frequency is still checked.
        return tf.eval_grid_layout_into(freqs_hz, &mut []);
    }
    // Each part of the grid comes with the same part of every plane.
    let part = part_len(nf, threads);
    let mut parts: Vec<Vec<&mut [f64]>> = (0..nf.div_ceil(part)).map(|_| Vec::new()).collect();
    for plane in data.chunks_exact_mut(nf) {
        for (t, piece) in plane.chunks_mut(part).enumerate() {
            parts[t].push(piece);
        }
    }
    let jobs = freqs_hz.chunks(part).zip(parts);
    on_threads(jobs, threads, cancel, &|f, mut p: Vec<&mut [f64]>| {
        // Blocks small enough that their values are still in cache when they are checked.
        let mut start = 0;
        while start < f.len() {
            let end = (start + CHECK_BLOCK).min(f.len());
            let mut block: Vec<&mut [f64]> = p.iter_mut().map(|x| &mut x[start..end]).collect();
            tf.eval_grid_layout_into(&f[start..end], &mut block)?;
            check_finite(&f[start..end], &block)?;
            start = end;
        }
        Ok(())
    })?;
    Ok(())
}

/// Frequencies evaluated and checked at a time: 2048 x 88 bytes (Table I's 11 planes) stay in
/// the L2 cache between the two, so the finiteness check costs little.
const CHECK_BLOCK: usize = 2048;

/// Whether every value is finite: `v - v` is 0 for a finite value and NaN for inf or NaN, and
/// sums of those, kept in independent lanes, vectorize with plain SSE2.
#[allow(clippy::eq_op, reason = "`v - v` is the finiteness test")]
fn all_finite(values: &[f64]) -> bool {
    let mut lanes = [0.0f64; 8];
    let mut chunks = values.chunks_exact(8);
    for c in chunks.by_ref() {
        for (l, v) in lanes.iter_mut().zip(c) {
            *l += v - v;
        }
    }
    let tail: f64 = chunks.remainder().iter().map(|v| v - v).sum();
    (lanes.iter().sum::<f64>() + tail) == 0.0
}

/// The first frequency of `freqs_hz` at which a value of `planes` (one per plane, as long as
/// the grid) is not finite, as [`TfError::NotFinite`]: an overflow that no method reports
/// otherwise (a frequency or parameters beyond the range of `f64`), never a silent NaN.
fn check_finite(freqs_hz: &[f64], planes: &[&mut [f64]]) -> Result<(), TfError> {
    if planes.iter().all(|p| all_finite(p)) {
        return Ok(());
    }
    let first_bad = planes
        .iter()
        .filter_map(|p| p.iter().position(|v| !v.is_finite()))
        .min();
    match first_bad {
        None => Ok(()),
        Some(k) => Err(TfError::NotFinite {
            freq_hz: freqs_hz[k],
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::FreqError;
    use crate::model::Model;
    use crate::params::Params;
    use crate::tf::{plan, Method};

    /// Parts cover the grid: one per thread on one thread or a short grid, else about
    /// `PARTS_PER_THREAD` per thread of at least `MIN_PART_POINTS`; never more than
    /// `MAX_PART_POINTS` (the work between two polls of the cancellation token).
    #[test]
    fn parts_cover_the_grid() {
        assert_eq!(part_len(0, 2), 1);
        assert_eq!(part_len(10, 0), 10);
        assert_eq!(part_len(16_000, 1), 16_000);
        assert_eq!(part_len(100_000, 1), MAX_PART_POINTS);
        assert_eq!(part_len(100_000_000, 2), MAX_PART_POINTS);
        assert_eq!(part_len(3000, 2), 1500);
        assert_eq!(
            part_len(100_000, 2),
            100_000_usize.div_ceil(2 * PARTS_PER_THREAD)
        );
        assert_eq!(part_len(10_000, 2), MIN_PART_POINTS);
    }

    /// A grid cut into many more parts than threads (each thread taking the next part not
    /// yet taken): the values of one thread, bit for bit, and, with bad frequencies in several
    /// parts, the error of the first one in grid order, whichever thread meets which first.
    #[test]
    fn many_parts_give_one_threads_values_and_first_error() {
        let model = Model::new(&Params::table_i()).unwrap();
        let tf = plan(&model, &Request::all_tilt(), Method::PoleZero).unwrap();
        let n = 40 * MIN_PART_POINTS + 123;
        let freqs: Vec<f64> = (0..n)
            .map(|k| 1e-5 * 1e7_f64.powf(k as f64 / (n - 1) as f64))
            .collect();
        let block = 21;
        let mut one = vec![Complex64::new(f64::NAN, 0.0); n * block];
        eval_grid_threads(tf.as_ref(), &freqs, &mut one, 1, Destination::Reused).unwrap();
        for threads in [2, 3, 5] {
            assert!(freqs.len().div_ceil(part_len(n, threads)) > threads);
            let mut many = vec![Complex64::new(f64::NAN, 0.0); n * block];
            eval_grid_threads(tf.as_ref(), &freqs, &mut many, threads, Destination::Reused)
                .unwrap();
            assert!(
                one.iter()
                    .zip(&many)
                    .all(|(a, b)| a.re.to_bits() == b.re.to_bits()
                        && a.im.to_bits() == b.im.to_bits()),
                "{threads} threads"
            );
            // Bad frequencies late in the grid, then an earlier one: the earliest is reported.
            let mut bad = freqs.clone();
            let late = [n - 1, n - 3 * MIN_PART_POINTS, n / 2];
            for (j, &k) in late.iter().enumerate() {
                bad[k] = -(j as f64) - 1.0;
                let got =
                    eval_grid_threads(tf.as_ref(), &bad, &mut many, threads, Destination::Reused);
                let Err(TfError::Freq(FreqError::Invalid { value, .. })) = got else {
                    panic!("{threads} threads: a negative frequency must fail, got {got:?}");
                };
                assert_eq!(value, bad[k], "{threads} threads");
            }
        }
    }

    /// An empty grid gives an empty matrix with the plan's labels; an empty request still
    /// checks every frequency.
    #[test]
    fn empty_grids_and_requests() {
        let model = Model::new(&Params::table_i()).unwrap();
        for method in [Method::Direct, Method::PoleZero] {
            let tf = plan(&model, &Request::all_tilt(), method).unwrap();
            let m = evaluate(tf.as_ref(), &[]).unwrap();
            assert_eq!((m.n_stored_freqs(), m.outputs.len()), (0, 7));
            assert!(m.dense_values().is_empty());
            let empty = Request {
                outputs: vec![],
                inputs: Request::all_tilt().inputs,
            };
            let tf = plan(&model, &empty, method).unwrap();
            let m = evaluate(tf.as_ref(), &[1e-3, 1.0]).unwrap();
            assert_eq!(m.n_stored_freqs(), 2);
            assert!(matches!(
                evaluate(tf.as_ref(), &[1e-3, -1.0]),
                Err(TfError::Freq(_))
            ));
        }
    }
}

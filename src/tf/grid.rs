//! Evaluation of a plan on a frequency grid: into a caller's dense buffer
//! ([`eval_grid_threads`]), or into a [`TransferMatrix`] in the plan's own [`Layout`]
//! ([`evaluate`], [`evaluate_into`]), on one or more threads.

use super::buffer::zeroed_f64;
use super::{Request, TransferFunction, TransferMatrix};
use crate::error::TfError;
use num_complex::Complex64;

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

/// Evaluates part of a grid into its part of an output buffer.
type EvalPart<'a, T> = dyn Fn(&[f64], &mut [T]) -> Result<(), TfError> + Sync + 'a;

/// `eval(part of freqs_hz, its part of out)` on `threads` contiguous parts of the grid, one
/// per thread (`std::thread::scope`; the first part on the calling thread); `per_freq` values
/// of `out` per frequency. The error of the first failing part in grid order.
fn on_threads<T: Send>(
    freqs_hz: &[f64],
    out: &mut [T],
    per_freq: usize,
    threads: usize,
    eval: &EvalPart<'_, T>,
) -> Result<(), TfError> {
    let part = freqs_hz.len().div_ceil(threads.max(1)).max(1);
    if part >= freqs_hz.len() || per_freq == 0 {
        return eval(freqs_hz, out);
    }
    let mut parts = freqs_hz.chunks(part).zip(out.chunks_mut(part * per_freq));
    let (f0, o0) = parts.next().expect("at least two parts");
    std::thread::scope(|scope| {
        let others: Vec<_> = parts
            .map(|(f, o)| scope.spawn(move || eval(f, o)))
            .collect();
        let first = eval(f0, o0);
        // In grid order: the first part's error, else the first failing other part's.
        others.into_iter().fold(first, |acc, h| {
            let r = h
                .join()
                .expect("transfer-function evaluation thread panicked");
            acc.and(r)
        })
    })
}

/// [`TransferFunction::eval_grid_into`] (dense `[freq][output][input]` complex values) with
/// the grid cut into `threads` contiguous parts, one per thread. The values do not depend on
/// `threads` (every point is evaluated independently); the error is the one of the first
/// failing frequency in grid order, as with one thread. `threads = 0` means 1.
///
/// # Panics
///
/// If `out` has the wrong length.
pub fn eval_grid_threads(
    tf: &dyn TransferFunction,
    freqs_hz: &[f64],
    out: &mut [Complex64],
    threads: usize,
) -> Result<(), TfError> {
    let block = check_grid_len(tf.request(), freqs_hz, out);
    on_threads(freqs_hz, out, block, threads, &|f, o| {
        tf.eval_grid_into(f, o)
    })
}

/// Evaluates a plan on every frequency of a grid, on one thread, into a new matrix in the
/// plan's [`Layout`] ([`TransferFunction::layout`]). Stops at the first singular frequency.
pub fn evaluate(tf: &dyn TransferFunction, freqs_hz: &[f64]) -> Result<TransferMatrix, TfError> {
    let layout = tf.layout();
    let data = zeroed_f64(layout.stride() * freqs_hz.len());
    let r = tf.request();
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
    let r = tf.request();
    out.freqs_hz.clear();
    out.freqs_hz.extend_from_slice(freqs_hz);
    out.outputs.clone_from(&r.outputs);
    out.inputs.clone_from(&r.inputs);
    out.method = tf.method();
    let (layout, data) = out.parts_mut();
    *layout = tf.layout();
    let stride = layout.stride();
    let len = stride * freqs_hz.len();
    if data.capacity() < len {
        *data = zeroed_f64(len);
    } else {
        data.resize(len, 0.0);
    }
    on_threads(freqs_hz, data, stride, threads, &|f, o| {
        tf.eval_grid_layout_into(f, o)
    })
}

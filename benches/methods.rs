//! Speed of each transfer-function method: the full 7x3 tilt matrix ([`Request::all_tilt`]: X, Y,
//! Z, theta, eta, phi, phi_a from theta_t, eta_t, phi_t) of Table I on a log-spaced grid from 1e-5
//! to 100 Hz.
//!
//! Group `methods_7x3_tilt`, one benchmark per method and thread count:
//! * `direct/1t`, `block/1t`, `split/1t`, `polezero/1t`, `modal/1t`, `statespace/1t`: one
//!   thread, `eval_into` at every grid point into a preallocated `[freq][output][input]`
//!   buffer (point by point);
//! * `block/2t`, `split/2t`, `polezero/2t`: the same with the grid cut into two halves, the
//!   second half evaluated on a thread spawned with `std::thread::scope` per iteration, the
//!   first on the calling thread (the spawn, tens of microseconds, is included and is
//!   negligible against the milliseconds of a grid);
//! * `polezero_matrix/1t`, `polezero_matrix/2t`: [`tf::evaluate_into`] into a reused
//!   `TransferMatrix`, one and two threads: what `tf::evaluate` (and so `auto`, which picks
//!   `polezero` for the 7x3 tilt matrix) computes, minus the allocation of the result. The
//!   matrix is in the plan's layout: the 11 entries of the 7x3 tilt matrix that are not
//!   structural zeros, real for the undamped Table I (88 bytes per point);
//! * `polezero_batch/1t`, `polezero_batch/2t`: `TransferFunction::eval_grid_into` (one thread)
//!   and `tf::eval_grid_threads(.., 2)`: the same values as the dense complex 7x3 matrix,
//!   structural zeros and zero imaginary parts included, as NumPy's H (336 bytes per point),
//!   into a reused buffer (huge pages advised, as `tf::evaluate` does);
//! * `polezero_evaluate/1t`: `tf::evaluate` itself, which also allocates its result (fresh
//!   pages: 8.8 MB at 1e5 points) and copies the grid.
//!
//! Group `polezero_as_built_7x3_tilt`: the pole-zero method on the symmetric Table I and, side
//! by side in the same run, on two pendulums as built whose offsets along x couple the blocks
//! (the 8x8 system: 21 entries of 8 factors over 8 poles, against 11 entries over two 4x4
//! blocks): the crossbar's centre of mass 1 mm off along x, and the test mass's (some entries
//! with conjugate pairs of complex zeros, still real arithmetic). `<model>/matrix` is
//! `tf::evaluate_into` into the plan's own layout (what `auto` hands the user), `<model>/batch`
//! `eval_grid_into` into the dense complex matrix; one thread. The cost ratio coupled /
//! symmetric per point is read from one run.
//!
//! Group `polezero_ground`: the pole-zero method on the 7x3 tilt matrix and on the 7x6 ground
//! matrix (tilt and the floor's translation x_t, y_t, z_t), side by side in one run:
//! `tilt_7x3/batch`, `ground_7x6/batch` (`eval_grid_into`, the dense complex matrix) and
//! `tilt_7x3/matrix`, `ground_7x6/matrix` (`tf::evaluate_into`, the plan's layout: 11 and 21
//! real entries), one thread each.
//!
//! The plan (`tf::plan`: normal modes, block matrices, forcing forms) is built once, outside the
//! timing; it is amortized over the grid. Throughput is in grid points, so ns per point is the
//! time per iteration divided by the grid size.
//!
//! The grid has 1e4 points by default; `TILTNOISE_BENCH_METHODS_POINTS` changes that
//! (`scripts/bench/compare_methods.py` sets 1e5, the target's grid). Sampling is flat with 10
//! samples, 0.3 s warm-up and 1 s measurement: a run takes about 10 s at 1e4 points and 10 to
//! 20 s at 1e5 (criterion then stretches the measurement of the slow methods and says so).
//!
//! Run with `cargo bench --bench methods`; CI only builds it (`cargo bench --no-run`). The
//! machine is shared and has 2 cores: read ratios measured in one run, not absolute times.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use num_complex::Complex64;
use tiltnoise_core::freq::log_grid;
use tiltnoise_core::model::{Input, Model, Observable};
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{self, Destination, Method, Request, TransferFunction};

/// Environment variable that overrides the grid size.
const POINTS_VAR: &str = "TILTNOISE_BENCH_METHODS_POINTS";
const DEFAULT_POINTS: usize = 10_000;
const F_LO_HZ: f64 = 1e-5;
const F_HI_HZ: f64 = 100.0;

fn n_points() -> usize {
    match std::env::var(POINTS_VAR) {
        Ok(s) => s
            .trim()
            .parse()
            .ok()
            .filter(|&n: &usize| n >= 2)
            .unwrap_or_else(|| panic!("{POINTS_VAR}={s:?}: need an integer >= 2")),
        Err(_) => DEFAULT_POINTS,
    }
}

/// `tf` at every frequency of `grid`, into `out` (`grid.len()` blocks of `block` values). A
/// point the method reports singular costs what it costs and is skipped (the untimed pass in
/// `methods` allows such points only for `statespace`, a comparison method, and counts them).
fn eval_grid(tf: &dyn TransferFunction, grid: &[f64], block: usize, out: &mut [Complex64]) {
    for (&f, h) in grid.iter().zip(out.chunks_exact_mut(block)) {
        let _ = tf.eval_into(f, h);
    }
}

/// The same, with the second half of the grid on a second thread.
fn eval_grid_2t(tf: &dyn TransferFunction, grid: &[f64], block: usize, out: &mut [Complex64]) {
    let mid = grid.len() / 2;
    let (g0, g1) = grid.split_at(mid);
    let (o0, o1) = out.split_at_mut(mid * block);
    std::thread::scope(|s| {
        s.spawn(|| eval_grid(tf, g1, block, o1));
        eval_grid(tf, g0, block, o0);
    });
}

fn methods(c: &mut Criterion) {
    let model = Model::new(&Params::table_i()).expect("Table I is valid");
    let request = Request::all_tilt();
    let block = request.outputs.len() * request.inputs.len();
    let n = n_points();
    let grid = log_grid(F_LO_HZ, F_HI_HZ, n).expect("valid grid");
    eprintln!(
        "methods bench: 7x3 tilt matrix, {n} log-spaced points {F_LO_HZ:e}..{F_HI_HZ} Hz \
         ({POINTS_VAR}={n})"
    );
    // Huge pages advised, as for a result of `tf::evaluate` (src/tf/buffer.rs).
    let mut out = tf::zeroed_complex(block * n);

    let mut g = c.benchmark_group("methods_7x3_tilt");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .throughput(Throughput::Elements(n as u64));
    for method in [
        Method::Direct,
        Method::Block,
        Method::Split,
        Method::PoleZero,
        Method::Modal,
        Method::StateSpace,
    ] {
        let plan = tf::plan(&model, &request, method).expect("full-model methods plan 7x3 tilt");
        let plan = plan.as_ref();
        // One untimed pass: fails loudly if a grid point is singular for a method that should
        // evaluate the whole grid; counts the state-space method's refusals.
        let singular = grid
            .iter()
            .zip(out.chunks_exact_mut(block))
            .map(|(&f, h)| plan.eval_into(f, h))
            .filter(Result::is_err)
            .count();
        if method == Method::StateSpace {
            eprintln!("methods bench: statespace reports {singular} of {n} points singular");
        } else {
            assert_eq!(
                singular,
                0,
                "{}: singular points on the grid",
                method.name()
            );
        }
        g.bench_function(format!("{}/1t", method.name()), |b| {
            b.iter(|| eval_grid(plan, black_box(&grid), block, black_box(&mut out)))
        });
        if matches!(method, Method::Block | Method::Split | Method::PoleZero) {
            g.bench_function(format!("{}/2t", method.name()), |b| {
                b.iter(|| eval_grid_2t(plan, black_box(&grid), block, black_box(&mut out)))
            });
        }
        if method == Method::PoleZero {
            // What `tf::evaluate` (and so `auto`) does: the batch evaluation of the whole grid.
            g.bench_function(format!("{}_batch/1t", method.name()), |b| {
                b.iter(|| {
                    plan.eval_grid_into(black_box(&grid), black_box(&mut out))
                        .expect("no singular frequency on the grid")
                })
            });
            // The same through `tf::evaluate`, which also allocates the result (fresh pages of
            // 34 MB at 1e5 points) and copies the grid: what a caller of `evaluate` pays.
            g.bench_function(format!("{}_evaluate/1t", method.name()), |b| {
                b.iter(|| tf::evaluate(plan, black_box(&grid)).expect("no singular frequency"))
            });
            g.bench_function(format!("{}_batch/2t", method.name()), |b| {
                b.iter(|| {
                    tf::eval_grid_threads(
                        plan,
                        black_box(&grid),
                        black_box(&mut out),
                        2,
                        Destination::Reused,
                    )
                    .expect("no singular frequency on the grid")
                })
            });
            // What `auto` hands the user: the plan's own layout (11 real entries of the 7x3
            // tilt matrix, the structural zeros implicit), into a reused `TransferMatrix`.
            let mut m = tf::evaluate(plan, &grid).expect("no singular frequency");
            for threads in [1, 2] {
                g.bench_function(format!("{}_matrix/{threads}t", method.name()), |b| {
                    b.iter(|| {
                        tf::evaluate_into(plan, black_box(&grid), threads, black_box(&mut m))
                            .expect("no singular frequency on the grid")
                    })
                });
            }
        }
    }
    g.finish();
}

fn as_built(c: &mut Criterion) {
    let request = Request::all_tilt();
    let block = request.outputs.len() * request.inputs.len();
    let n = n_points();
    let grid = log_grid(F_LO_HZ, F_HI_HZ, n).expect("valid grid");
    let mut out = tf::zeroed_complex(block * n);
    let mut g = c.benchmark_group("polezero_as_built_7x3_tilt");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .throughput(Throughput::Elements(n as u64));
    let set = |key: &str| {
        Params::table_i()
            .with_override(&format!("asymmetry.{key}=1e-3"))
            .expect("a 1 mm offset is valid")
    };
    for (name, params) in [
        ("symmetric", Params::table_i()),
        ("crossbar_x_1mm", set("crossbar_com_x_m")),
        ("tm_x_1mm", set("tm_com_x_m")),
    ] {
        let model = Model::new(&params).expect("valid parameters");
        let plan = tf::plan(&model, &request, Method::PoleZero).expect("pole-zero plans 7x3 tilt");
        let plan = plan.as_ref();
        let mut m = tf::evaluate(plan, &grid).expect("no singular frequency");
        eprintln!(
            "polezero_as_built: {name}: {} planes of the compact layout per point",
            plan.layout().n_planes()
        );
        g.bench_function(format!("{name}/matrix"), |b| {
            b.iter(|| {
                tf::evaluate_into(plan, black_box(&grid), 1, black_box(&mut m))
                    .expect("no singular frequency on the grid")
            })
        });
        g.bench_function(format!("{name}/batch"), |b| {
            b.iter(|| {
                plan.eval_grid_into(black_box(&grid), black_box(&mut out))
                    .expect("no singular frequency on the grid")
            })
        });
    }
    g.finish();
}

/// The pole-zero method's cost per point with the six ground inputs against the three tilt
/// inputs (module docs).
fn polezero_ground(c: &mut Criterion) {
    let model = Model::new(&Params::table_i()).expect("Table I is valid");
    let n = n_points();
    let grid = log_grid(F_LO_HZ, F_HI_HZ, n).expect("valid grid");
    let mut g = c.benchmark_group("polezero_ground");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .throughput(Throughput::Elements(n as u64));
    for (name, inputs) in [
        ("tilt_7x3", Input::all_tilts()),
        ("ground_7x6", Input::all_ground()),
    ] {
        let request = Request {
            outputs: Observable::ALL.to_vec(),
            inputs,
        };
        let plan = tf::plan(&model, &request, Method::PoleZero).expect("polezero plans it");
        let plan = plan.as_ref();
        let mut out = tf::zeroed_complex(request.outputs.len() * request.inputs.len() * n);
        g.bench_function(format!("{name}/batch"), |b| {
            b.iter(|| {
                plan.eval_grid_into(black_box(&grid), black_box(&mut out))
                    .expect("no singular frequency on the grid")
            })
        });
        let mut m = tf::evaluate(plan, &grid).expect("no singular frequency");
        g.bench_function(format!("{name}/matrix"), |b| {
            b.iter(|| {
                tf::evaluate_into(plan, black_box(&grid), 1, black_box(&mut m))
                    .expect("no singular frequency on the grid")
            })
        });
    }
    g.finish();
}

criterion_group!(benches, methods, as_built, polezero_ground);
criterion_main!(benches);

//! The transfer-function, methods and Monte Carlo jobs: their numbers are the library's own
//! (bit for bit), a grid streamed in blocks gives the matrix computed whole, and options that
//! do not fit fail naming their key.

use tiltnoise_core::freq::LogGrid;
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::limits::MAX_GRID_POINTS;
use tiltnoise_core::mc::{self, McConfig};
use tiltnoise_core::model::{Input, Model, Observable, Request};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{self, Method, TransferMatrix};
use tiltnoise_job::methods::MethodsRequest;
use tiltnoise_job::monte_carlo::{self, McRequest};
use tiltnoise_job::tf::{FreqGrid, TfRequest};
use tiltnoise_job::{Cancel, JobError, Silent};

fn model() -> Model {
    Model::new(&Params::table_i()).unwrap()
}

fn ground_request() -> Request {
    Request {
        outputs: Observable::ALL.to_vec(),
        inputs: Input::all_ground(),
    }
}

fn request(model: &Model, grid: FreqGrid) -> TfRequest<'_> {
    TfRequest {
        model,
        request: ground_request(),
        grid,
        per: GroundQuantity::Displacement,
        method: None,
        rel_tol: None,
        block_freqs: None,
        figure: None,
        figure_options: Default::default(),
        invocation: Default::default(),
    }
}

/// Frequencies from below the first mode to above the last, none on a mode.
fn freqs() -> Vec<f64> {
    (0..97).map(|k| 1e-4 * 1.13f64.powi(k)).collect()
}

fn assert_same_bits(a: &TransferMatrix, b: &TransferMatrix) {
    assert_eq!(a.freqs_hz, b.freqs_hz);
    assert_eq!((&a.outputs, &a.inputs), (&b.outputs, &b.inputs));
    let bits = |m: &TransferMatrix| -> Vec<(u64, u64)> {
        m.dense_values()
            .iter()
            .map(|z| (z.re.to_bits(), z.im.to_bits()))
            .collect()
    };
    assert_eq!(bits(a), bits(b));
}

#[test]
fn the_tf_job_gives_the_librarys_transfer_functions_bit_for_bit() {
    let model = model();
    let result = tiltnoise_job::tf::run(
        &request(&model, FreqGrid::Points(freqs())),
        &Cancel::never(),
        &Silent,
    )
    .unwrap();
    let choice = result.choice.expect("auto reports its pick");
    let plan = tf::plan(&model, &ground_request(), choice.method).unwrap();
    let direct = tf::evaluate(plan.as_ref(), &freqs()).unwrap();
    assert_same_bits(&result.tf, &direct);

    // Per unit floor acceleration: the library's conversion of the same matrix.
    let mut req = request(&model, FreqGrid::Points(freqs()));
    req.per = GroundQuantity::Acceleration;
    req.method = Some(choice.method);
    let per = tiltnoise_job::tf::run(&req, &Cancel::never(), &Silent).unwrap();
    assert!(per.choice.is_none(), "a method asked for is not chosen");
    let expected = direct
        .per_ground_quantity(
            GroundQuantity::Acceleration,
            &tf::LowFrequency::new(&model, &ground_request()),
        )
        .unwrap();
    assert_same_bits(&per.tf, &expected);
}

#[test]
fn a_grid_streamed_in_blocks_gives_the_matrix_computed_whole() {
    let model = model();
    let grid = LogGrid::new(1e-4, 30.0, 101, MAX_GRID_POINTS).unwrap();
    let mut req = request(&model, FreqGrid::Log(grid));
    req.block_freqs = Some(7);
    let planned = tiltnoise_job::tf::prepare(&req).unwrap();
    let whole = planned.whole(&Cancel::never()).unwrap();
    let mut freqs = Vec::new();
    let mut values = Vec::new();
    let mut reported = Vec::new();
    planned
        .blocks(&Cancel::never(), |block, done| -> Result<(), JobError> {
            assert!(block.freqs_hz.len() <= 7);
            freqs.extend_from_slice(&block.freqs_hz);
            values.extend(block.dense_values());
            reported.push(done);
            Ok(())
        })
        .unwrap();
    assert_eq!(freqs, whole.freqs_hz);
    assert_eq!(freqs, grid.block(0, grid.len()));
    assert_eq!(values, whole.dense_values());
    assert_eq!(reported.last(), Some(&101));
    assert_eq!(reported.len(), 101usize.div_ceil(7));
}

#[test]
fn options_that_do_not_fit_fail_naming_their_key() {
    let model = model();
    let key_of = |e: &JobError| match e {
        JobError::Option { option, .. } => *option,
        other => panic!("not an option error: {other}"),
    };

    let mut req = request(&model, FreqGrid::Points(freqs()));
    req.rel_tol = Some(0.0);
    let e = tiltnoise_job::tf::prepare(&req).err().unwrap();
    assert_eq!(key_of(&e), OptionKey::REL_TOL);
    assert_eq!(
        e.message(),
        "rel_tol 0: the tolerance must be a finite relative error in (0, 1)"
    );

    let mut req = request(&model, FreqGrid::Points(freqs()));
    req.block_freqs = Some(0);
    assert_eq!(
        key_of(&tiltnoise_job::tf::prepare(&req).err().unwrap()),
        OptionKey::BLOCK_FREQS
    );

    // 0 Hz has no value per unit floor velocity: refused before anything is computed.
    let mut req = request(&model, FreqGrid::Points(vec![1e-3, 0.0]));
    req.per = GroundQuantity::Velocity;
    let e = tiltnoise_job::tf::prepare(&req).err().unwrap();
    assert_eq!(key_of(&e), OptionKey::PER);
    assert!(
        e.message()
            .starts_with("per velocity: frequency 2 of freq_hz is 0 Hz"),
        "{e}"
    );
    // Forces and torques stay per N and N m, where 0 Hz is fine.
    let mut req = request(&model, FreqGrid::Points(vec![0.0, 1e-3]));
    req.per = GroundQuantity::Velocity;
    req.request.inputs = vec![Input::Force(tiltnoise_core::model::ForceInput::ALL[0])];
    assert!(tiltnoise_job::tf::prepare(&req).is_ok());

    // A figure is drawn from a grid held whole.
    let big = LogGrid::new(1e-4, 30.0, MAX_GRID_POINTS + 1, usize::MAX).unwrap();
    let mut req = request(&model, FreqGrid::Log(big));
    req.figure = Some("tf.png".into());
    let e = tiltnoise_job::tf::prepare(&req).err().unwrap();
    assert_eq!(key_of(&e), OptionKey::SAVE);
    assert!(e.message().contains("and freq_hz asks for"), "{e}");
}

#[test]
fn auto_next_to_a_mode_says_what_to_do_in_the_front_ends_spelling() {
    let model = model();
    let nu_3 = NormalModes::new(&model).frequencies_hz()[2];
    let mut req = request(&model, FreqGrid::Points(vec![nu_3 * 1.001]));
    req.request.inputs = vec![Input::all_tilts()[1]];
    let e = tiltnoise_job::tf::prepare(&req).err().unwrap();
    assert!(matches!(e, JobError::NoMethod(_)), "{e}");
    // Without a front end's style a key is shown as itself, `key=value` given.
    assert!(
        e.message()
            .ends_with("(method=polezero, or another freq_hz)"),
        "{e}"
    );
}

#[test]
fn the_methods_job_measures_every_method_and_names_autos_pick() {
    let model = model();
    let grid: Vec<f64> = (0..20).map(|k| 1e-3 * 1.4f64.powi(k)).collect();
    let req = MethodsRequest {
        model: &model,
        grid_hz: grid.clone(),
        inputs: None,
        grid_spec: String::new(),
        view: Default::default(),
        invocation: Default::default(),
    };
    let result = tiltnoise_job::methods::run(&req, &Cancel::never(), &Silent).unwrap();
    let names: Vec<Method> = result.rows.iter().map(|r| r.method).collect();
    assert_eq!(names, Method::ALL.to_vec());
    let expected = tiltnoise_job::tf::choose(
        &model,
        &Request::all_tilt(),
        (grid[0], grid[19]),
        result.target_rel_err,
    )
    .unwrap();
    assert_eq!(result.auto.as_ref().ok(), Some(&expected.method));
    assert_eq!(result.matrix_label(), "7x3 tilt matrix");

    for bad in [vec![], vec![1e-3, -1.0], vec![f64::NAN]] {
        let req = MethodsRequest {
            model: &model,
            grid_hz: bad.clone(),
            inputs: None,
            grid_spec: String::new(),
            view: Default::default(),
            invocation: Default::default(),
        };
        match tiltnoise_job::methods::run(&req, &Cancel::never(), &Silent) {
            Err(JobError::Option {
                option: OptionKey::FREQ_HZ,
                ..
            }) => {}
            Err(e) => panic!("{bad:?}: {e}"),
            Ok(_) => panic!("{bad:?} accepted"),
        }
    }
}

#[test]
fn the_monte_carlo_job_gives_the_librarys_draws() {
    let params = Params::table_i();
    let req = McRequest {
        params: &params,
        samples: 200,
        seed: 11,
        threads: 2,
        invocation: tiltnoise_job::Invocation::default(),
        figure: tiltnoise_job::figures::View::default(),
    };
    let run = monte_carlo::run(&req, &Cancel::never(), &tiltnoise_job::Silent).unwrap();
    let cfg = McConfig {
        samples: 200,
        seed: 11,
        threads: 1,
        ..McConfig::default_for(&params)
    };
    assert_eq!(run.result, mc::run(&params, &cfg, &|_| {}).unwrap());
    let nominal = NormalModes::new(&Model::new(&params).unwrap()).frequencies_hz();
    assert_eq!(run.nominal_hz.to_vec(), nominal);
    assert!(monte_carlo::caption(&run).contains("200 draws"));

    let e = monte_carlo::check(&McRequest {
        samples: usize::MAX,
        ..req.clone()
    })
    .unwrap_err();
    assert!(e.message().contains("samples"), "{e}");
    let e = monte_carlo::run(
        &McRequest { samples: 0, ..req },
        &Cancel::never(),
        &tiltnoise_job::Silent,
    );
    assert!(matches!(e, Err(JobError::MonteCarlo(_))));
}

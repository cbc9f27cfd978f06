//! The default frequency grid never misses a resonance: undamped poles are bracketed closely
//! on both sides without being hit; damped peaks get points across their half-power width.

use tiltnoise_core::freq::{default_grid, DEFAULT_F_HI_HZ, DEFAULT_F_LO_HZ};
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{plan, Method, Request};

#[test]
fn undamped_poles_are_bracketed_within_1e_6_and_never_hit() {
    let model = Model::new(&Params::table_i()).unwrap();
    let grid = default_grid(&model);
    assert!(
        grid.windows(2).all(|w| w[0] < w[1]),
        "sorted, no duplicates"
    );
    assert_eq!(
        (grid[0], *grid.last().unwrap()),
        (DEFAULT_F_LO_HZ, DEFAULT_F_HI_HZ)
    );
    let tf = plan(&model, &Request::all_tilt(), Method::Direct).unwrap();
    for mode in NormalModes::new(&model).modes {
        let f = mode.frequency_hz;
        let below = grid
            .iter()
            .filter(|&&g| g < f)
            .map(|g| (f - g) / f)
            .fold(1.0, f64::min);
        let above = grid
            .iter()
            .filter(|&&g| g > f)
            .map(|g| (g - f) / f)
            .fold(1.0, f64::min);
        assert!(
            below <= 1e-6 && above <= 1e-6,
            "nu_{}: {below:e} {above:e}",
            mode.index
        );
        assert!(!grid.contains(&f));
    }
    // And the whole grid evaluates: no point is singular.
    for &f in &grid {
        tf.eval(f).unwrap_or_else(|e| panic!("{f} Hz: {e}"));
    }
}

#[test]
fn damped_peaks_are_sampled_across_their_width() {
    // Loss on the torsion fibres: the torsion modes get a half-power half-width f phi_k / 2.
    let p = Params::table_i()
        .with_override("loss.torsion_a_rad=1e-3")
        .unwrap()
        .with_override("loss.torsion_b_rad=1e-3")
        .unwrap();
    let model = Model::new(&p).unwrap();
    let grid = default_grid(&model);
    let k_imag = model.stiffness_complex().map(|z| z.im);
    for mode in NormalModes::new(&model).modes.iter().take(2) {
        let f = mode.frequency_hz;
        let phi = (mode.shape.transpose() * k_imag * mode.shape)[(0, 0)] / mode.omega_sq;
        assert!(phi > 5e-4, "torsion modes are damped: phi_k = {phi}");
        let half_width = f * phi / 2.0;
        let inside = grid
            .iter()
            .filter(|&&g| (g - f).abs() <= half_width)
            .count();
        assert!(
            inside >= 5,
            "nu_{}: {inside} points within the half-width",
            mode.index
        );
        // The peak value itself is on the grid (damped: not singular).
        assert!(
            grid.iter().any(|&g| ((g - f) / f).abs() < 1e-15),
            "nu_{} centre",
            mode.index
        );
    }
}

use super::*;
use crate::dd::Dd;

fn with(sets: &[&str]) -> Params {
    sets.iter()
        .fold(Params::table_i(), |p, s| p.with_override(s).unwrap())
}

const CASES: [&[&str]; 3] = [
    &[
        "asymmetry.tm_com_x_m=1e-3",
        "asymmetry.crossbar_com_y_m=-5e-4",
    ],
    &["asymmetry.crossbar_com_x_m=1e-3"],
    &[
        "asymmetry.lower_attachment_x_m=2e-3",
        "asymmetry.sensor_rot_z_rad=1e-3",
    ],
];

/// The `f64` linearization against the double-double one at the same rest configuration (the
/// `f64` one, exact in both): every entry within its own running rounding bound,
/// `CLEAN_DEPTH eps mag`.
#[test]
fn f64_linearization_is_within_its_rounding_bound() {
    for sets in CASES {
        let p = with(sets);
        let a = linearize::<f64>(&p).unwrap();
        let rest = a.rest.map(|t| Tracked::exact(Dd::from_f64(t.value)));
        let b = at_rest(&Consts::<Tracked<Dd>>::new(&p), rest);
        let mut worst = 0.0_f64;
        let mut check = |what: &str, x: Tracked<f64>, y: Tracked<Dd>| {
            let diff = (x.value - y.value.to_f64()).abs();
            let bound = CLEAN_DEPTH * f64::EPSILON * x.mag;
            worst = worst.max(diff / bound);
            assert!(
                diff <= bound,
                "{sets:?} {what}: {:e} vs {:e}, bound {bound:e}",
                x.value,
                y.value.to_f64()
            );
        };
        for i in 0..8 {
            for j in 0..8 {
                check("M", a.mass[i][j], b.mass[i][j]);
                check("K", a.stiffness_gravity[i][j], b.stiffness_gravity[i][j]);
            }
            for j in 0..12 {
                check("B", a.force[i][j], b.force[i][j]);
            }
            for j in 0..6 {
                check("G0", a.ground_g0[i][j], b.ground_g0[i][j]);
                check("G2", a.ground_g2[i][j], b.ground_g2[i][j]);
            }
            for j in 0..7 {
                check("C", a.observation[j][i], b.observation[j][i]);
            }
        }
        println!("{sets:?}: worst {worst:.2e} of the rounding bound");
    }
}

/// The `f64` rest configuration is the double-double one to the `f64` floor of Newton's
/// method: the energy of the difference, `dq^T K dq`, is at most that of the gradient's
/// rounding, `(c eps)^2 E` with `E` the gravity stiffness scale and `c = CLEAN_DEPTH`.
#[test]
fn f64_rest_configuration_is_at_the_f64_floor() {
    for sets in CASES {
        let p = with(sets);
        let a = linearize::<f64>(&p).unwrap();
        let b = linearize::<Dd>(&p).unwrap();
        let dq: [f64; 8] = std::array::from_fn(|k| a.rest[k].value - b.rest[k].value.to_f64());
        let k = &b.stiffness_gravity;
        let mut energy = 0.0;
        for i in 0..8 {
            for j in 0..8 {
                energy += dq[i] * k[i][j].value.to_f64() * dq[j];
            }
        }
        let elastic = [
            (2, p.torsion.k_a_n_m_per_rad),
            (6, p.torsion.k_b_n_m_per_rad),
            (3, p.bouncing.kappa_a_n_per_m),
            (7, p.bouncing.kappa_b_n_per_m),
        ];
        energy += elastic.iter().map(|&(i, k)| k * dq[i] * dq[i]).sum::<f64>();
        let l = &p.length;
        let scale = p.environment.g_m_per_s2
            * (p.mass.m_a_kg * (l.z_m + l.z_a_m) + p.mass.m_b_kg * (l.z_m + l.z_b_m));
        let bound = (CLEAN_DEPTH * f64::EPSILON).powi(2) * scale;
        println!("{sets:?}: dq {dq:?}, energy {energy:e} (bound {bound:e})");
        assert!(energy <= bound, "{sets:?}: energy {energy:e} > {bound:e}");
    }
}

//! Independent cross-check of the linear model against the energies of section II of the paper.
//!
//! The kinematics of section II.A (eq. matriceR, r_g,a and r_g,b), with the [asymmetry]
//! offsets of the pendulum as built (centres of mass and the lower clamp displaced in their
//! bodies' axes, the readout axes turned), are evaluated on hyper-dual numbers, which carry
//! exact first and mixed second derivatives, and every matrix of the library is rebuilt from
//! them at the library's rest configuration `q0` (0 for the symmetric pendulum), without any of
//! the Appendix A formulas or the library's kinematics:
//!
//! * grad U = 0 at `q0`: the library's rest configuration is an equilibrium of these energies;
//! * K  = Hessian of the potential U of section II.D at `q0`;
//! * M  from T = 1/2 sum m |J q'|^2 + 1/2 w.I.w, with J = dr_g/dq and [w]x = A^T dA/dq_h;
//! * B  (zeroth-order generalized forces, eq. qh) = [J_a^T, J_b^T, W_a^T, W_b^T] (inertial axes);
//! * G0 by tilting the direction of gravity, G2 from the apparent forces of section IV.B;
//! * the floor translation's G2 from the kinetic energy in the inertial frame, where a centre of
//!   mass moves at `u' + J q'`: the cross term `sum m (J q') . u'` of T puts
//!   `-sum m J^T u'' = w^2 (sum m J^T) u` on the right of Lagrange's equations, so
//!   `G2[h][k] = d^2 T / dq'_h du'_k`;
//! * C  from the cube-centre position and the attitudes of A_b and A_a, in the readout's axes.
//!
//! K and M are also checked against numerical Hessians of the exact energies at the tilted
//! rest configuration: central differences of the exact gradient (K) and of the positions and
//! attitudes (M, through the kinetic energy), with the truncation error measured by halving
//! the step.
//!
//! Each hyper-dual component also carries the sum of the absolute values of the terms added into
//! it (running error analysis), which gives every entry its own rounding scale, including the
//! entries where large terms cancel (e.g. m_a g y_a - m_b g d = 0 in K[eta_a, phi_a]).

use crate::tolerances::ENERGY_C_TOL;
use nalgebra::{Matrix4, SMatrix, Vector4};
use std::ops::{Add, Mul, Neg, Sub};
use tiltnoise_core::model::{Coord, ForceInput, Model, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::params::Params;

// ------------------------------------------------------------------------------------------------
// Hyper-dual numbers a + b e1 + c e2 + d e1e2 (e1^2 = e2^2 = 0), with term magnitudes.
// ------------------------------------------------------------------------------------------------

/// `v` = (a, b, c, d); `m[k]` = sum of the absolute values of the terms summed into `v[k]`.
#[derive(Clone, Copy, Debug)]
struct Hd {
    v: [f64; 4],
    m: [f64; 4],
}

impl Hd {
    fn cst(x: f64) -> Hd {
        Hd {
            v: [x, 0.0, 0.0, 0.0],
            m: [x.abs(), 0.0, 0.0, 0.0],
        }
    }

    /// A variable with value `x`, seeded along e1 and/or e2.
    fn var(x: f64, e1: bool, e2: bool) -> Hd {
        let (b, c) = (f64::from(u8::from(e1)), f64::from(u8::from(e2)));
        Hd {
            v: [x, b, c, 0.0],
            m: [x.abs(), b, c, 0.0],
        }
    }

    /// Component k (0: value, 1: e1, 2: e2, 3: e1e2) as a constant, keeping its magnitude.
    fn part(self, k: usize) -> Hd {
        Hd {
            v: [self.v[k], 0.0, 0.0, 0.0],
            m: [self.m[k], 0.0, 0.0, 0.0],
        }
    }

    /// f(x) for f, f', f'' evaluated at the real part: f(a) + f'(a) (b e1 + c e2 + d e1e2)
    /// + f''(a) b c e1e2.
    fn chain(self, f: f64, df: f64, d2f: f64) -> Hd {
        let ([_, b, c, d], [_, mb, mc, md]) = (self.v, self.m);
        Hd {
            v: [f, df * b, df * c, df * d + d2f * b * c],
            m: [
                f.abs(),
                df.abs() * mb,
                df.abs() * mc,
                df.abs() * md + d2f.abs() * mb * mc,
            ],
        }
    }

    fn sin(self) -> Hd {
        let a = self.v[0];
        self.chain(a.sin(), a.cos(), -a.sin())
    }

    fn cos(self) -> Hd {
        let a = self.v[0];
        self.chain(a.cos(), -a.sin(), -a.cos())
    }
}

impl Add for Hd {
    type Output = Hd;
    fn add(self, o: Hd) -> Hd {
        Hd {
            v: std::array::from_fn(|k| self.v[k] + o.v[k]),
            m: std::array::from_fn(|k| self.m[k] + o.m[k]),
        }
    }
}

impl Sub for Hd {
    type Output = Hd;
    fn sub(self, o: Hd) -> Hd {
        self + (-o)
    }
}

impl Neg for Hd {
    type Output = Hd;
    fn neg(self) -> Hd {
        Hd {
            v: self.v.map(|x| -x),
            m: self.m,
        }
    }
}

impl Mul for Hd {
    type Output = Hd;
    fn mul(self, o: Hd) -> Hd {
        let prod = |x: [f64; 4], y: [f64; 4]| {
            [
                x[0] * y[0],
                x[0] * y[1] + x[1] * y[0],
                x[0] * y[2] + x[2] * y[0],
                x[0] * y[3] + x[1] * y[2] + x[2] * y[1] + x[3] * y[0],
            ]
        };
        Hd {
            v: prod(self.v, o.v),
            m: prod(self.m, o.m),
        }
    }
}

type V3 = [Hd; 3];
type M3 = [[Hd; 3]; 3];

fn dot(a: V3, b: V3) -> Hd {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn scale(s: Hd, a: V3) -> V3 {
    a.map(|x| s * x)
}

fn add3(a: V3, b: V3) -> V3 {
    std::array::from_fn(|k| a[k] + b[k])
}

fn transpose(a: M3) -> M3 {
    std::array::from_fn(|r| std::array::from_fn(|c| a[c][r]))
}

fn mat_mul(a: M3, b: M3) -> M3 {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c])
    })
}

fn mat_vec(a: M3, x: V3) -> V3 {
    a.map(|row| dot(row, x))
}

fn column(a: M3, c: usize) -> V3 {
    [a[0][c], a[1][c], a[2][c]]
}

/// The axial vector of a skew matrix [w]x.
fn vee(s: M3) -> V3 {
    [s[2][1], s[0][2], s[1][0]]
}

fn part3(a: V3, k: usize) -> V3 {
    a.map(|x| x.part(k))
}

fn part33(a: M3, k: usize) -> M3 {
    a.map(|r| r.map(|x| x.part(k)))
}

/// Eq. (matriceR): rotation by theta about x, then eta about the new y, then phi about the new z.
fn rot(theta: Hd, eta: Hd, phi: Hd) -> M3 {
    let (st, ct, se, ce, sp, cp) = (
        theta.sin(),
        theta.cos(),
        eta.sin(),
        eta.cos(),
        phi.sin(),
        phi.cos(),
    );
    [
        [ce * cp, se * st * cp + ct * sp, st * sp - se * ct * cp],
        [-(ce * sp), ct * cp - se * st * sp, se * ct * sp + st * cp],
        [se, -(ce * st), ce * ct],
    ]
}

// ------------------------------------------------------------------------------------------------
// The model of section II, from the energies.
// ------------------------------------------------------------------------------------------------

/// Parameters as hyper-dual constants.
struct Phys {
    m_a: Hd,
    m_b: Hd,
    g: Hd,
    i_a: M3,
    i_b: M3,
    k_a: Hd,
    k_b: Hd,
    kappa_a: Hd,
    kappa_b: Hd,
    d: Hd,
    z: Hd,
    z_a: Hd,
    z_b: Hd,
    h_c: Hd,
    h: Hd,
    y_a: Hd,
    /// Offsets of the crossbar's and the test mass's centres of mass and of the lower clamp
    /// (x, y in the body's axes).
    crossbar: [Hd; 2],
    tm: [Hd; 2],
    clamp: [Hd; 2],
    /// The readout's components of a lab vector: `R(s) v`.
    readout: M3,
}

impl Phys {
    fn new(p: &Params) -> Phys {
        let c = Hd::cst;
        let i = &p.inertia;
        let a = &p.asymmetry;
        let zero = c(0.0);
        Phys {
            m_a: c(p.mass.m_a_kg),
            m_b: c(p.mass.m_b_kg),
            g: c(p.environment.g_m_per_s2),
            i_a: [
                [c(i.a11_kg_m2), zero, zero],
                [zero, c(i.a22_kg_m2), c(i.a23_kg_m2)],
                [zero, c(i.a23_kg_m2), c(i.a33_kg_m2)],
            ],
            // The full tensor: the library's I^b_22-for-eta generalization must then agree.
            i_b: [
                [c(i.b11_kg_m2), zero, zero],
                [zero, c(i.b22_kg_m2), zero],
                [zero, zero, c(i.b33_kg_m2)],
            ],
            k_a: c(p.torsion.k_a_n_m_per_rad),
            k_b: c(p.torsion.k_b_n_m_per_rad),
            kappa_a: c(p.bouncing.kappa_a_n_per_m),
            kappa_b: c(p.bouncing.kappa_b_n_per_m),
            d: c(p.length.d_m),
            z: c(p.length.z_m),
            z_a: c(p.length.z_a_m),
            z_b: c(p.length.z_b_m),
            h_c: c(p.length.h_c_m),
            h: c(p.length.h_m),
            // Section II.A: the whole system's centre of mass is on the upper fibre.
            y_a: c(p.length.d_m * p.mass.m_b_kg / p.mass.m_a_kg),
            crossbar: [c(a.crossbar_com_x_m), c(a.crossbar_com_y_m)],
            tm: [c(a.tm_com_x_m), c(a.tm_com_y_m)],
            clamp: [c(a.lower_attachment_x_m), c(a.lower_attachment_y_m)],
            readout: rot(
                c(a.sensor_rot_x_rad),
                c(a.sensor_rot_y_rad),
                c(a.sensor_rot_z_rad),
            ),
        }
    }
}

/// Body-to-enclosure rotations and positions (relative to the upper suspension point).
struct Kin {
    a_a: M3,
    a_b: M3,
    r_ga: V3,
    r_gb: V3,
    /// Cube geometric centre, h_c below G_b along -u_3,b.
    r_c: V3,
}

/// q = (theta_a, eta_a, phi_a, delta_a, theta_b, eta_b, phi_b, delta_b).
fn kinematics(ph: &Phys, q: &[Hd; 8]) -> Kin {
    let r_a = rot(q[0], q[1], q[2]);
    let r_b = rot(q[4], q[5], q[6]);
    let a_a = transpose(r_a); // u_i,a = R_a^T e_i: column i of A_a
    let a_b = mat_mul(a_a, transpose(r_b)); // u_i,b = R_a^T R_b^T e_i
    let (u1a, u2a, u3a) = (column(a_a, 0), column(a_a, 1), column(a_a, 2));
    let (u1b, u2b, u3b) = (column(a_b, 0), column(a_b, 1), column(a_b, 2));
    // The crossbar's centre of mass: Z_a below the upper fibre's lower end, y_a along the arm,
    // plus its offset in the crossbar's axes.
    let r_ga = add3(
        add3(
            scale(-(ph.z + ph.z_a + q[3]), u3a),
            scale(ph.y_a + ph.crossbar[1], u2a),
        ),
        scale(ph.crossbar[0], u1a),
    );
    // The lower clamp, at the arm's end (0, -d) plus its offset; the test mass hangs from it
    // along its own axis u_3b, its centre of mass offset in its own axes.
    let clamp = add3(
        add3(scale(-(ph.z + q[3]), u3a), scale(ph.clamp[1] - ph.d, u2a)),
        scale(ph.clamp[0], u1a),
    );
    let r_gb = add3(
        add3(clamp, scale(-(ph.z_b + q[7]), u3b)),
        add3(scale(ph.tm[0], u1b), scale(ph.tm[1], u2b)),
    );
    // The cube centre: on the fibre's axis, h_c below the nominal centre of mass.
    let r_c = add3(clamp, scale(-(ph.z_b + q[7] + ph.h_c), u3b));
    Kin {
        a_a,
        a_b,
        r_ga,
        r_gb,
        r_c,
    }
}

/// U(q, t) of section II.D with gravity tilted by t = (theta_t, eta_t, phi_t).
///
/// Tilt convention (the library's): t is the rotation taking the floor frame to the inertial
/// frame, so the floor basis is rotated by -t: f_i = A(-t) e_i in inertial components, where
/// A(s) = R(s)^T ≈ I + [s]x is the active rotation by s (R of eq. matriceR). The inertial "up"
/// e_z has floor components f_i . e_z = e_i . A(-t)^T e_z = e_i . A(t) e_z + O(t^2) (only the
/// first order in t enters G0), so up = R(t)^T e_z = third row of R(t) ≈ (eta_t, -theta_t, 1).
/// The pendulum hangs along up, u_3,a ≈ (eta_a, -theta_a, 1), i.e. at theta_a = +theta_t:
/// Y -> +theta_t (Z + Z_b + h_c), as the paper states (checked by the static-tilt test).
fn potential(ph: &Phys, q: &[Hd; 8], t: &[Hd; 3]) -> Hd {
    let kin = kinematics(ph, q);
    let up = rot(t[0], t[1], t[2])[2];
    let gravity = ph.g * (ph.m_a * dot(up, kin.r_ga) + ph.m_b * dot(up, kin.r_gb));
    let half = Hd::cst(0.5);
    let elastic = half
        * (ph.k_a * q[2] * q[2]
            + ph.k_b * q[6] * q[6]
            + ph.kappa_a * q[3] * q[3]
            + ph.kappa_b * q[7] * q[7]);
    // Static pre-tension of the fibres, 1/2 kappa (delta + delta_0)^2 with kappa delta_0 = T:
    // linear in delta alone, so it leaves the Hessian untouched and only cancels the gravity
    // gradient along delta (checked: grad U = 0 at q = 0).
    let pretension = (ph.m_a + ph.m_b) * ph.g * q[3] + ph.m_b * ph.g * q[7];
    gravity + elastic + pretension
}

/// N hyper-dual zeros, e1 seeded on index `e1`, e2 on `e2`.
fn seeds<const N: usize>(e1: Option<usize>, e2: Option<usize>) -> [Hd; N] {
    at_seeds(&[0.0; N], e1, e2)
}

/// The values `x`, e1 seeded on index `e1`, e2 on `e2`.
fn at_seeds<const N: usize>(x: &[f64; N], e1: Option<usize>, e2: Option<usize>) -> [Hd; N] {
    std::array::from_fn(|k| Hd::var(x[k], e1 == Some(k), e2 == Some(k)))
}

/// Every matrix of the linear model, rebuilt from the energies; entries carry magnitudes.
struct Reference {
    grad: [Hd; 8],
    k: [[Hd; 8]; 8],
    m: [[Hd; 8]; 8],
    b: [[Hd; 12]; 8],
    g0: [[Hd; 3]; 8],
    g2: [[Hd; 3]; 8],
    /// Floor translation: generalized force per unit `w^2 u`.
    translation_g2: [[Hd; 3]; 8],
    c: [[Hd; 8]; 7],
}

impl Reference {
    /// Every matrix at the configuration `q0`.
    fn build(ph: &Phys, q0: &[f64; 8]) -> Reference {
        let t0 = seeds::<3>(None, None);
        let q = |e1, e2| at_seeds(q0, e1, e2);
        let grad = std::array::from_fn(|i| potential(ph, &q(Some(i), None), &t0).part(1));
        let k = std::array::from_fn(|i| {
            std::array::from_fn(|j| potential(ph, &q(Some(i), Some(j)), &t0).part(3))
        });
        // Generalized force per unit tilt: Q = -dU/dq, linear part in t.
        let g0 = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                -potential(ph, &q(Some(i), None), &seeds(None, Some(j))).part(3)
            })
        });

        // First-order kinematics per unit q'_h at q0.
        let mut j_a = [[Hd::cst(0.0); 3]; 8];
        let mut j_b = j_a;
        let (mut wa_body, mut wb_body, mut wa_in, mut wb_in, mut dr_c) = (j_a, j_a, j_a, j_a, j_a);
        for h in 0..8 {
            let kin = kinematics(ph, &q(Some(h), None));
            j_a[h] = part3(kin.r_ga, 1);
            j_b[h] = part3(kin.r_gb, 1);
            dr_c[h] = part3(kin.r_c, 1);
            let (a0, da) = (part33(kin.a_a, 0), part33(kin.a_a, 1));
            wa_body[h] = vee(mat_mul(transpose(a0), da)); // [w']x = A^T dA
            wa_in[h] = vee(mat_mul(da, transpose(a0))); // [w]x = dA A^T
            let (b0, db) = (part33(kin.a_b, 0), part33(kin.a_b, 1));
            wb_body[h] = vee(mat_mul(transpose(b0), db));
            wb_in[h] = vee(mat_mul(db, transpose(b0)));
        }

        let m = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                ph.m_a * dot(j_a[i], j_a[j])
                    + ph.m_b * dot(j_b[i], j_b[j])
                    + dot(wa_body[i], mat_vec(ph.i_a, wa_body[j]))
                    + dot(wb_body[i], mat_vec(ph.i_b, wb_body[j]))
            })
        });

        // Eq. (qh) at q0: Q_h = dr_g/dq_h . F + dpsi/dq_h . M for both bodies.
        let b: [[Hd; 12]; 8] = std::array::from_fn(|h| {
            [j_a[h], j_b[h], wa_in[h], wb_in[h]]
                .concat()
                .try_into()
                .unwrap()
        });

        // Apparent forces per unit t'' (section IV.B): w' = -t'', r_s'' = w' x (0, 0, h).
        let kin0 = kinematics(ph, &q(None, None));
        let (r_ga0, r_gb0) = (part3(kin0.r_ga, 0), part3(kin0.r_gb, 0));
        // Inertia tensors in lab axes at q0: A I A^T.
        let lab = |a: M3, i: M3| {
            let a = part33(a, 0);
            mat_mul(mat_mul(a, i), transpose(a))
        };
        let (i_a, i_b) = (lab(kin0.a_a, ph.i_a), lab(kin0.a_b, ph.i_b));
        let zero = Hd::cst(0.0);
        let mut g2 = [[zero; 3]; 8];
        for axis in 0..3 {
            let w_dot: V3 = std::array::from_fn(|k| Hd::cst(if k == axis { -1.0 } else { 0.0 }));
            let r_s = cross(w_dot, [zero, zero, ph.h]);
            let force = |mass: Hd, r_g: V3| scale(-mass, add3(r_s, cross(w_dot, r_g)));
            let torque = |inertia: M3| mat_vec(inertia, w_dot).map(|x| -x);
            let inputs = [
                force(ph.m_a, r_ga0),
                force(ph.m_b, r_gb0),
                torque(i_a),
                torque(i_b),
            ]
            .concat();
            for (row, b_row) in g2.iter_mut().zip(&b) {
                let q = b_row
                    .iter()
                    .zip(&inputs)
                    .fold(zero, |acc, (&bb, &f)| acc + bb * f);
                row[axis] = -q; // t'' = -w^2 t for a harmonic tilt
            }
        }

        // Floor translation: T = 1/2 sum m |u' + J q'|^2 with u' seeded on e2 and q'_h on e1;
        // the mixed part is d^2 T / dq'_h du'_k.
        let half = Hd::cst(0.5);
        let translation_g2 = std::array::from_fn(|h| {
            std::array::from_fn(|k| {
                let q_dot = seeds::<8>(Some(h), None);
                let u_dot = seeds::<3>(None, Some(k));
                let velocity =
                    |jac: &[V3; 8]| (0..8).fold(u_dot, |v, i| add3(v, scale(q_dot[i], jac[i])));
                let (v_a, v_b) = (velocity(&j_a), velocity(&j_b));
                (half * (ph.m_a * dot(v_a, v_a) + ph.m_b * dot(v_b, v_b))).part(3)
            })
        });

        // Observables: X, Y, Z of the cube centre, TM attitude, crossbar torsion, in the
        // readout's axes.
        let readout = |v: V3| mat_vec(ph.readout, v);
        let c = std::array::from_fn(|r| {
            std::array::from_fn(|h| match r {
                0..=2 => readout(dr_c[h])[r],
                3..=5 => readout(wb_in[h])[r - 3],
                _ => readout(wa_in[h])[2],
            })
        });

        Reference {
            grad,
            k,
            m,
            b,
            g0,
            g2,
            translation_g2,
            c,
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Comparison.
// ------------------------------------------------------------------------------------------------

/// Checks one entry; returns |lib - ref| / mag (0 for structural zeros).
/// A structural zero is an entry into which no nonzero term enters (mag == 0, hence ref == 0):
/// the library must then hold exactly 0.0.
fn assert_close(set: &str, matrix: &str, row: &str, col: &str, lib: f64, reference: Hd) -> f64 {
    let (r, mag) = (reference.v[0], reference.m[0]);
    if mag == 0.0 {
        assert!(
            r == 0.0 && lib == 0.0,
            "[{set}] {matrix}[{row}, {col}]: structural zero in the energy reference \
             (no term enters), but library = {lib:e}"
        );
        return 0.0;
    }
    let tol = ENERGY_C_TOL * f64::EPSILON * mag;
    let diff = (lib - r).abs();
    assert!(
        diff <= tol,
        "[{set}] {matrix}[{row}, {col}]: library = {lib:e}, energy reference = {r:e}, \
         |diff| = {diff:e} > tol = {tol:e} (= {ENERGY_C_TOL} eps x term magnitude {mag:e})"
    );
    diff / mag
}

/// Compares a whole matrix; returns the largest relative discrepancy and the number of
/// structural zeros.
fn compare<const R: usize, const C: usize>(
    set: &str,
    matrix: &str,
    rows: [&str; R],
    cols: [&str; C],
    lib: &SMatrix<f64, R, C>,
    reference: &[[Hd; C]; R],
) -> (f64, usize) {
    let mut max_rel = 0.0_f64;
    let mut zeros = 0;
    for (r, ref_row) in reference.iter().enumerate() {
        for (c, &entry) in ref_row.iter().enumerate() {
            max_rel = max_rel.max(assert_close(
                set,
                matrix,
                rows[r],
                cols[c],
                lib[(r, c)],
                entry,
            ));
            zeros += usize::from(entry.m[0] == 0.0);
        }
    }
    (max_rel, zeros)
}

fn coord_names() -> [&'static str; 8] {
    Coord::ALL.map(Coord::name)
}

/// Symmetry of the reference within its own rounding bound.
fn assert_reference_symmetric(set: &str, matrix: &str, a: &[[Hd; 8]; 8]) {
    let names = coord_names();
    for i in 0..8 {
        for j in 0..i {
            let (x, y) = (a[i][j], a[j][i]);
            let tol = ENERGY_C_TOL * f64::EPSILON * x.m[0].max(y.m[0]);
            assert!(
                (x.v[0] - y.v[0]).abs() <= tol,
                "[{set}] reference {matrix} not symmetric at [{}, {}]: {:e} vs {:e}",
                names[i],
                names[j],
                x.v[0],
                y.v[0]
            );
        }
    }
}

/// Full cross-check of one parameter set; prints the largest discrepancy per matrix.
/// The library's rest configuration (0 for the symmetric pendulum).
fn rest_of(model: &Model) -> [f64; 8] {
    std::array::from_fn(|k| model.rest_configuration()[k])
}

fn crosscheck(set: &str, p: &Params) {
    let model = Model::new(p).expect("valid parameter set");
    let ph = Phys::new(p);
    let q0 = rest_of(&model);
    let r = Reference::build(&ph, &q0);
    let names = coord_names();

    // Equilibrium: y_a = d m_b / m_a and the pre-tension make q = 0 stationary; an offset
    // tilts the bodies to the library's q0. Its f64 rounding (half an ulp of each coordinate;
    // the library solves in double-double) leaves sum_j |K_ij| u |q0_j| of gradient. (It
    // moves every matrix entry by about u |q0| of its magnitude, 1e-19 for millimetre offsets:
    // far below the rounding bound of the comparisons below.)
    for (i, g) in r.grad.iter().enumerate() {
        let rounding: f64 = (0..8)
            .map(|j| r.k[i][j].v[0].abs() * 0.5 * f64::EPSILON * q0[j].abs())
            .sum();
        let tol = ENERGY_C_TOL * f64::EPSILON * g.m[0] + rounding;
        assert!(
            g.v[0].abs() <= tol,
            "[{set}] reference dU/d({}) = {:e} at q0 (tol {tol:e}): not an equilibrium",
            names[i],
            g.v[0]
        );
    }
    assert_reference_symmetric(set, "M", &r.m);
    assert_reference_symmetric(set, "K", &r.k);

    let (mass, stiffness) = (*model.mass(), model.stiffness());
    for i in 0..8 {
        for j in 0..i {
            for (what, a) in [("M", &mass), ("K", &stiffness)] {
                assert!(
                    a[(i, j)] == a[(j, i)],
                    "[{set}] library {what} not symmetric at [{}, {}]: {:e} vs {:e}",
                    names[i],
                    names[j],
                    a[(i, j)],
                    a[(j, i)]
                );
            }
        }
    }

    let forces = ForceInput::ALL.map(ForceInput::name);
    let tilts = TiltAxis::ALL.map(TiltAxis::name);
    let observables = Observable::ALL.map(Observable::name);
    let tilt = model.tilt_forcing();
    let results = [
        ("M", compare(set, "M", names, names, &mass, &r.m)),
        ("K", compare(set, "K", names, names, &stiffness, &r.k)),
        (
            "B",
            compare(set, "B", names, forces, model.force_matrix(), &r.b),
        ),
        ("G0", compare(set, "G0", names, tilts, &tilt.g0, &r.g0)),
        ("G2", compare(set, "G2", names, tilts, &tilt.g2, &r.g2)),
        (
            "G2_u",
            compare(
                set,
                "G2_u",
                names,
                TranslationAxis::ALL.map(TranslationAxis::name),
                &model.translation_forcing().g2,
                &r.translation_g2,
            ),
        ),
        (
            "C",
            compare(set, "C", observables, names, model.observation(), &r.c),
        ),
    ];
    for (matrix, (max_rel, zeros)) in results {
        println!(
            "[{set}] {matrix:>2}: max |lib - ref| / term magnitude = {max_rel:.2e} \
             (tol {:.2e}); structural zeros: {zeros}",
            ENERGY_C_TOL * f64::EPSILON
        );
    }
}

/// K and M against numerical Hessians of the exact energies at the library's rest
/// configuration. K: central differences of the exact gradient (the hyper-dual first
/// derivative) with steps `h` and `h/2`; M: the kinetic energy `T(v)` of a velocity `v`, with
/// the velocities of the centres of mass and the bodies' angular velocities from central
/// differences of the positions and attitudes (steps `tau`, `tau/2`), and `M_ij = T(e_i + e_j)
/// - T(e_i) - T(e_j)` (exact for a quadratic form). Each estimate at the smaller step must be
/// within twice its truncation error, measured as the change from the larger step (central
/// differences are O(h^2): the error at h/2 is a third of that change), plus the rounding of
/// the differences, `ENERGY_C_TOL eps` of the differenced magnitudes over the step.
fn numerical_hessians(set: &str, p: &Params) {
    let model = Model::new(p).expect("valid parameter set");
    let ph = Phys::new(p);
    let q0 = rest_of(&model);
    let names = coord_names();
    let t0 = seeds::<3>(None, None);
    let shifted = |j: usize, h: f64| {
        let mut q = q0;
        q[j] += h;
        q
    };
    let grad = |q: &[f64; 8], i: usize| potential(&ph, &at_seeds(q, Some(i), None), &t0).part(1);
    let k_at = |h: f64| -> [[(f64, f64); 8]; 8] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let (a, b) = (grad(&shifted(j, h), i), grad(&shifted(j, -h), i));
                ((a.v[0] - b.v[0]) / (2.0 * h), (a.m[0] + b.m[0]) / (2.0 * h))
            })
        })
    };
    let h = 1e-5;
    let (coarse, fine) = (k_at(h), k_at(h / 2.0));
    let stiffness = model.stiffness();
    let (mut worst, mut resolved) = (0.0_f64, 0);
    for i in 0..8 {
        for j in 0..8 {
            let ((kc, _), (kf, mag)) = (coarse[i][j], fine[i][j]);
            let tol = 2.0 * (kc - kf).abs() + ENERGY_C_TOL * f64::EPSILON * mag;
            let diff = (kf - stiffness[(i, j)]).abs();
            // The entries the differences resolve (tolerance below the entry).
            if tol < stiffness[(i, j)].abs() {
                worst = worst.max(diff / stiffness[(i, j)].abs());
                resolved += 1;
            }
            assert!(
                diff <= tol,
                "[{set}] numerical K[{}, {}] = {kf:e}, library {:e}, tol {tol:e}",
                names[i],
                names[j],
                stiffness[(i, j)]
            );
        }
    }
    println!(
        "[{set}] numerical Hessian of U: max |K_num - K| / |K| = {worst:.1e} over the \
         {resolved} entries it resolves"
    );

    // Kinetic energy of the velocity v at q0, and its rounding scale.
    let kin = |q: &[f64; 8]| kinematics(&ph, &at_seeds(q, None, None));
    let energy = |v: &[f64; 8], tau: f64| -> (f64, f64) {
        let step = |sign: f64| -> [f64; 8] { std::array::from_fn(|k| q0[k] + sign * tau * v[k]) };
        let (p, m, c) = (kin(&step(1.0)), kin(&step(-1.0)), kin(&q0));
        let velocity = |a: V3, b: V3| -> [f64; 3] {
            std::array::from_fn(|k| (a[k].v[0] - b[k].v[0]) / (2.0 * tau))
        };
        let position_scale = |a: V3| a.iter().map(|x| x.m[0]).fold(0.0, f64::max);
        let mut t = 0.0;
        let mut scale = 0.0;
        for (mass, a, b, r) in [
            (ph.m_a.v[0], p.r_ga, m.r_ga, c.r_ga),
            (ph.m_b.v[0], p.r_gb, m.r_gb, c.r_gb),
        ] {
            let u = velocity(a, b);
            let speed_sq: f64 = u.iter().map(|x| x * x).sum();
            t += 0.5 * mass * speed_sq;
            // |d(v^2)| <= 2 |v| |dv|, |dv| <= ENERGY_C_TOL eps |r| / tau per component.
            scale += mass * speed_sq.sqrt() * 3.0 * position_scale(r) / tau;
        }
        for (a_p, a_m, a_0, inertia) in
            [(p.a_a, m.a_a, c.a_a, ph.i_a), (p.a_b, m.a_b, c.a_b, ph.i_b)]
        {
            // w' = vee(skew(A^T A')) with A' from the central difference (unit attitude
            // entries: their differences err by eps / tau).
            let da: M3 = std::array::from_fn(|r| {
                std::array::from_fn(|k| Hd::cst((a_p[r][k].v[0] - a_m[r][k].v[0]) / (2.0 * tau)))
            });
            let s = mat_mul(transpose(part33(a_0, 0)), da);
            let w: [f64; 3] = [
                0.5 * (s[2][1].v[0] - s[1][2].v[0]),
                0.5 * (s[0][2].v[0] - s[2][0].v[0]),
                0.5 * (s[1][0].v[0] - s[0][1].v[0]),
            ];
            let iw: [f64; 3] =
                std::array::from_fn(|r| (0..3).map(|k| inertia[r][k].v[0] * w[k]).sum());
            t += 0.5 * (0..3).map(|k| w[k] * iw[k]).sum::<f64>();
            let norm_i: f64 = inertia.iter().flatten().map(|x| x.v[0].abs()).sum();
            scale += norm_i * w.iter().map(|x| x.abs()).sum::<f64>() * 3.0 / tau;
        }
        (t, scale)
    };
    let unit = |i: usize| -> [f64; 8] { std::array::from_fn(|k| f64::from(u8::from(k == i))) };
    let m_at = |tau: f64| -> [[(f64, f64); 8]; 8] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let (ti, si) = energy(&unit(i), tau);
                if i == j {
                    return (2.0 * ti, 2.0 * si);
                }
                let both: [f64; 8] = std::array::from_fn(|k| unit(i)[k] + unit(j)[k]);
                let (tb, sb) = energy(&both, tau);
                let (tj, sj) = energy(&unit(j), tau);
                (tb - ti - tj, sb + si + sj)
            })
        })
    };
    let tau = 1e-5;
    let (coarse, fine) = (m_at(tau), m_at(tau / 2.0));
    let mass = model.mass();
    let (mut worst, mut resolved) = (0.0_f64, 0);
    for i in 0..8 {
        for j in 0..8 {
            let ((mc, _), (mf, scale)) = (coarse[i][j], fine[i][j]);
            let tol = 2.0 * (mc - mf).abs() + ENERGY_C_TOL * f64::EPSILON * scale;
            let diff = (mf - mass[(i, j)]).abs();
            // The entries the differences resolve (tolerance below the entry).
            if tol < mass[(i, j)].abs() {
                worst = worst.max(diff / mass[(i, j)].abs());
                resolved += 1;
            }
            assert!(
                diff <= tol,
                "[{set}] numerical M[{}, {}] = {mf:e}, library {:e}, tol {tol:e}",
                names[i],
                names[j],
                mass[(i, j)]
            );
        }
    }
    println!(
        "[{set}] numerical Hessian of T: max |M_num - M| / |M| = {worst:.1e} over the \
         {resolved} entries it resolves"
    );
}

/// Table I with I^b_22 far from I^b_11, a different I^a_23 (other sign) and a different h.
fn altered() -> Params {
    [
        "inertia.b22_kg_m2=6.5e-4",
        "inertia.a23_kg_m2=3.0e-2",
        "length.h_m=1.3",
    ]
    .iter()
    .fold(Params::table_i(), |p, s| p.with_override(s).expect(s))
}

/// Every length, mass and inertia moved away from Table I (Z_a > Z_b reversed, h_c larger...).
fn generic() -> Params {
    [
        "mass.m_a_kg=0.93",
        "mass.m_b_kg=0.37",
        "inertia.a11_kg_m2=0.151",
        "inertia.a22_kg_m2=0.213",
        "inertia.a33_kg_m2=3.1e-2",
        "inertia.a23_kg_m2=-1.7e-2",
        "inertia.b11_kg_m2=4.1e-4",
        "inertia.b22_kg_m2=1.9e-4",
        "inertia.b33_kg_m2=7.7e-5",
        "torsion.k_a_n_m_per_rad=3.3e-6",
        "torsion.k_b_n_m_per_rad=1.3e-8",
        "bouncing.kappa_a_n_per_m=3900",
        "bouncing.kappa_b_n_per_m=520",
        "length.d_m=0.21",
        "length.h_c_m=0.057",
        "length.z_m=1.07",
        "length.z_a_m=0.29",
        "length.z_b_m=0.64",
        "length.h_m=2.7",
        "environment.g_m_per_s2=9.7803",
    ]
    .iter()
    .fold(Params::table_i(), |p, s| p.with_override(s).expect(s))
}

/// Parameter sets of the pendulum as built: every kind of offset, alone and together (with
/// the generic lengths and inertias too), and a readout rotation.
fn as_built() -> Vec<(&'static str, Params)> {
    let set =
        |base: Params, sets: &[&str]| sets.iter().fold(base, |p, s| p.with_override(s).expect(s));
    vec![
        (
            "crossbar x 1 mm",
            set(Params::table_i(), &["asymmetry.crossbar_com_x_m=1e-3"]),
        ),
        (
            "test mass x 1 mm, y -0.4 mm",
            set(
                Params::table_i(),
                &["asymmetry.tm_com_x_m=1e-3", "asymmetry.tm_com_y_m=-4e-4"],
            ),
        ),
        (
            "crossbar y, clamp x and y, readout turned",
            set(
                Params::table_i(),
                &[
                    "asymmetry.crossbar_com_y_m=-2e-3",
                    "asymmetry.lower_attachment_x_m=1.5e-3",
                    "asymmetry.lower_attachment_y_m=7e-4",
                    "asymmetry.sensor_rot_x_rad=3e-3",
                    "asymmetry.sensor_rot_y_rad=-1e-3",
                    "asymmetry.sensor_rot_z_rad=2e-3",
                ],
            ),
        ),
        (
            "generic, every offset",
            set(
                generic(),
                &[
                    "asymmetry.crossbar_com_x_m=-8e-4",
                    "asymmetry.crossbar_com_y_m=1.2e-3",
                    "asymmetry.tm_com_x_m=2e-3",
                    "asymmetry.tm_com_y_m=5e-4",
                    "asymmetry.lower_attachment_x_m=-3e-4",
                    "asymmetry.lower_attachment_y_m=9e-4",
                    "asymmetry.sensor_rot_z_rad=-4e-3",
                ],
            ),
        ),
    ]
}

#[test]
fn as_built_parameters_match_energy_reference() {
    for (set, p) in as_built() {
        crosscheck(set, &p);
    }
}

#[test]
fn as_built_matches_numerical_hessians_of_the_energies() {
    for (set, p) in as_built() {
        numerical_hessians(set, &p);
    }
}

#[test]
fn table_i_matches_energy_reference() {
    crosscheck("Table I", &Params::table_i());
}

#[test]
fn altered_parameters_match_energy_reference() {
    let p = altered();
    assert!(p.inertia.b22_kg_m2 > 2.0 * p.inertia.b11_kg_m2);
    crosscheck("b22 != b11, a23, h", &p);
}

#[test]
fn generic_parameters_match_energy_reference() {
    crosscheck("generic", &generic());
}

/// The reference alone (no library matrix) reproduces the paper's quasi-static tilt limits
/// Y -> +theta_t (Z + Z_b + h_c) and X -> -eta_t (Z + Z_b + h_c): this pins the sign convention
/// of the tilted gravity independently of the library.
#[test]
fn reference_static_tilt_response_has_paper_sign() {
    for p in [Params::table_i(), altered(), generic()] {
        let ph = Phys::new(&p);
        let r = Reference::build(&ph, &[0.0; 8]);
        let lever = p.length.z_m + p.length.z_b_m + p.length.h_c_m;
        let y_block = [0, 3, 4, 7]; // theta_a, delta_a, theta_b, delta_b
        let x_block = [1, 2, 5, 6]; // eta_a, phi_a, eta_b, phi_b
        for (axis, block, obs, expected) in [
            (0, y_block, Observable::Y, lever),
            (1, x_block, Observable::X, -lever),
        ] {
            // K, the G0 column and the observation row do not couple outside the block
            // (structural zeros), so the 4x4 solve is the full 8x8 solve.
            for i in 0..8 {
                let inside = block.contains(&i);
                for j in 0..8 {
                    assert!(inside == block.contains(&j) || r.k[i][j].m[0] == 0.0);
                }
                assert!(inside || r.g0[i][axis].m[0] == 0.0);
                assert!(inside || r.c[obs.index()][i].m[0] == 0.0);
            }
            let k = Matrix4::from_fn(|a, b| r.k[block[a]][block[b]].v[0]);
            let rhs = Vector4::from_fn(|a, _| r.g0[block[a]][axis].v[0]);
            let q = k.lu().solve(&rhs).expect("stiffness block is regular");
            let observed: f64 = (0..4).map(|a| r.c[obs.index()][block[a]].v[0] * q[a]).sum();
            // LU is backward stable: relative error <= (few n) eps cond(K) on top of the
            // O(ENERGY_C_TOL eps) error of the data; ENERGY_C_TOL eps cond covers both.
            let eig = ((k + k.transpose()) * 0.5).symmetric_eigenvalues();
            let cond = eig.amax() / eig.iter().fold(f64::INFINITY, |m, x| m.min(x.abs()));
            let tol = ENERGY_C_TOL * f64::EPSILON * cond * lever;
            assert!(
                (observed - expected).abs() <= tol,
                "static response of {} to unit {}: {observed:e}, expected {expected:e} \
                 (tol {tol:e}, cond {cond:e})",
                obs.name(),
                TiltAxis::ALL[axis].name()
            );
        }
    }
}

/// The hyper-dual arithmetic gives exact derivatives: f = x sin(x) cos(y) at (0.3, -0.7).
#[test]
fn hyper_dual_derivatives_are_exact() {
    let (x0, y0) = (0.3_f64, -0.7_f64);
    let check = |e: [bool; 4], want: f64, k: usize| {
        let x = Hd::var(x0, e[0], e[1]);
        let y = Hd::var(y0, e[2], e[3]);
        let f = x * x.sin() * y.cos();
        let tol = ENERGY_C_TOL * f64::EPSILON * f.m[k];
        assert!((f.v[k] - want).abs() <= tol, "{:e} vs {want:e}", f.v[k]);
    };
    let (sx, cx, sy, cy) = (x0.sin(), x0.cos(), y0.sin(), y0.cos());
    check([true, false, false, true], -(sx + x0 * cx) * sy, 3); // f_xy
    check([true, true, false, false], (2.0 * cx - x0 * sx) * cy, 3); // f_xx
    check([false, false, true, true], -x0 * sx * cy, 3); // f_yy
    check([true, false, false, false], (sx + x0 * cx) * cy, 1); // f_x
    check([false, false, false, true], -x0 * sx * sy, 2); // f_y
}

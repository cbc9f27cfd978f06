//! The exact kinematics of section II.A with the `[asymmetry]` offsets, and the potential
//! energy of section II.D, for any [`Real`] scalar.
//!
//! Body frames: `A_a = R_a^T` (columns `u_1a, u_2a, u_3a`), `A_b = A_a R_b^T`, `R` of eq.
//! (matriceR). Positions relative to the upper suspension point:
//!
//! ```text
//! r_ga   = -(Z + delta_a + Z_a) u_3a + c_x u_1a + (y_a + c_y) u_2a
//! r_clamp = -(Z + delta_a) u_3a + l_x u_1a + (-d + l_y) u_2a
//! r_gb   = r_clamp - (Z_b + delta_b) u_3b + t_x u_1b + t_y u_2b
//! r_cube = r_clamp - (Z_b + delta_b + h_c) u_3b
//! ```
//!
//! with `(c_x, c_y)`, `(t_x, t_y)`, `(l_x, l_y)` the crossbar, test-mass and clamp offsets.
//! With every offset 0 these are the paper's `r_g,a`, eq. (rgb), and the cube centre `h_c`
//! below `G_b` on the lower fibre's axis.

use super::scalar::Real;
use crate::params::Params;

pub(super) type V3<T> = [T; 3];
pub(super) type M3<T> = [[T; 3]; 3];

/// The parameters in the scalar `T`.
#[derive(Debug, Clone)]
pub(super) struct Consts<T> {
    pub m_a: T,
    pub m_b: T,
    pub g: T,
    pub d: T,
    pub z: T,
    pub z_a: T,
    pub z_b: T,
    pub h_c: T,
    pub h: T,
    /// `d m_b / m_a`: the nominal crossbar centre of mass balances the test mass.
    pub y_a: T,
    /// Torsion `k_a`, `k_b` and bouncing `kappa_a`, `kappa_b` constants, on phi_a, phi_b,
    /// delta_a, delta_b.
    pub elastic: [(usize, T); 4],
    /// Inertia tensors about the centres of mass in body axes.
    pub i_a: M3<T>,
    pub i_b: M3<T>,
    /// `(c_x, c_y)`, `(t_x, t_y)`, `(l_x, l_y)`.
    pub crossbar: [T; 2],
    pub tm: [T; 2],
    pub clamp: [T; 2],
    /// Readout rotation angles about x, then y, then z.
    pub sensor: [T; 3],
}

impl<T: Real> Consts<T> {
    pub fn new(p: &Params) -> Consts<T> {
        let c = T::from_f64;
        let (i, l, a) = (&p.inertia, &p.length, &p.asymmetry);
        let (m_a, m_b, d) = (c(p.mass.m_a_kg), c(p.mass.m_b_kg), c(l.d_m));
        let zero = c(0.0);
        Consts {
            m_a,
            m_b,
            g: c(p.environment.g_m_per_s2),
            d,
            z: c(l.z_m),
            z_a: c(l.z_a_m),
            z_b: c(l.z_b_m),
            h_c: c(l.h_c_m),
            h: c(l.h_m),
            y_a: d * m_b / m_a,
            elastic: [
                (2, c(p.torsion.k_a_n_m_per_rad)),
                (6, c(p.torsion.k_b_n_m_per_rad)),
                (3, c(p.bouncing.kappa_a_n_per_m)),
                (7, c(p.bouncing.kappa_b_n_per_m)),
            ],
            i_a: [
                [c(i.a11_kg_m2), zero, zero],
                [zero, c(i.a22_kg_m2), c(i.a23_kg_m2)],
                [zero, c(i.a23_kg_m2), c(i.a33_kg_m2)],
            ],
            i_b: [
                [c(i.b11_kg_m2), zero, zero],
                [zero, c(i.b22_kg_m2), zero],
                [zero, zero, c(i.b33_kg_m2)],
            ],
            crossbar: [c(a.crossbar_com_x_m), c(a.crossbar_com_y_m)],
            tm: [c(a.tm_com_x_m), c(a.tm_com_y_m)],
            clamp: [c(a.lower_attachment_x_m), c(a.lower_attachment_y_m)],
            sensor: [
                c(a.sensor_rot_x_rad),
                c(a.sensor_rot_y_rad),
                c(a.sensor_rot_z_rad),
            ],
        }
    }

    /// The same values in another scalar (a constant of it).
    pub fn map<U>(&self, f: impl Fn(T) -> U) -> Consts<U> {
        let m3 = |m: &M3<T>| m.map(|r| r.map(&f));
        Consts {
            m_a: f(self.m_a),
            m_b: f(self.m_b),
            g: f(self.g),
            d: f(self.d),
            z: f(self.z),
            z_a: f(self.z_a),
            z_b: f(self.z_b),
            h_c: f(self.h_c),
            h: f(self.h),
            y_a: f(self.y_a),
            elastic: self.elastic.map(|(k, v)| (k, f(v))),
            i_a: m3(&self.i_a),
            i_b: m3(&self.i_b),
            crossbar: self.crossbar.map(&f),
            tm: self.tm.map(&f),
            clamp: self.clamp.map(&f),
            sensor: self.sensor.map(&f),
        }
    }
}

pub(super) fn dot<T: Real>(a: V3<T>, b: V3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross<T: Real>(a: V3<T>, b: V3<T>) -> V3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn axpy<T: Real>(s: T, x: V3<T>, y: V3<T>) -> V3<T> {
    std::array::from_fn(|k| s * x[k] + y[k])
}

pub(super) fn transpose<T: Copy>(a: &M3<T>) -> M3<T> {
    std::array::from_fn(|r| std::array::from_fn(|c| a[c][r]))
}

pub(super) fn mat_mul<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c])
    })
}

pub(super) fn mat_vec<T: Real>(a: &M3<T>, x: V3<T>) -> V3<T> {
    a.map(|row| dot(row, x))
}

fn column<T: Copy>(a: &M3<T>, c: usize) -> V3<T> {
    [a[0][c], a[1][c], a[2][c]]
}

/// Eq. (matriceR): the frame rotation by `theta` about x, then `eta` about the new y, then
/// `phi` about the new z (components of a vector in the rotated frame are `R v`).
pub(super) fn rot<T: Real>(theta: T, eta: T, phi: T) -> M3<T> {
    let ((st, ct), (se, ce), (sp, cp)) = (theta.sin_cos(), eta.sin_cos(), phi.sin_cos());
    [
        [ce * cp, se * st * cp + ct * sp, st * sp - se * ct * cp],
        [-(ce * sp), ct * cp - se * st * sp, se * ct * sp + st * cp],
        [se, -(ce * st), ce * ct],
    ]
}

/// The bodies' attitudes and the points the model needs, at configuration `q`.
pub(super) struct Pose<T> {
    /// Body-to-lab rotation of the crossbar (columns `u_1a, u_2a, u_3a`).
    pub a_a: M3<T>,
    /// Body-to-lab rotation of the test mass.
    pub a_b: M3<T>,
    pub r_ga: V3<T>,
    pub r_gb: V3<T>,
    /// The cube's geometric centre.
    pub r_cube: V3<T>,
}

/// `q = (theta_a, eta_a, phi_a, delta_a, theta_b, eta_b, phi_b, delta_b)`.
pub(super) fn pose<T: Real>(c: &Consts<T>, q: &[T; 8]) -> Pose<T> {
    let a_a = transpose(&rot(q[0], q[1], q[2]));
    let a_b = mat_mul(&a_a, &transpose(&rot(q[4], q[5], q[6])));
    let (u1a, u2a, u3a) = (column(&a_a, 0), column(&a_a, 1), column(&a_a, 2));
    let (u1b, u2b, u3b) = (column(&a_b, 0), column(&a_b, 1), column(&a_b, 2));
    let upper = c.z + q[3];
    let r_ga = axpy(
        -(upper + c.z_a),
        u3a,
        axpy(c.crossbar[0], u1a, u2a.map(|x| (c.y_a + c.crossbar[1]) * x)),
    );
    let r_clamp = axpy(
        -upper,
        u3a,
        axpy(c.clamp[0], u1a, u2a.map(|x| (c.clamp[1] - c.d) * x)),
    );
    let lower = c.z_b + q[7];
    let r_gb = axpy(-lower, u3b, axpy(c.tm[0], u1b, axpy(c.tm[1], u2b, r_clamp)));
    let r_cube = axpy(-(lower + c.h_c), u3b, r_clamp);
    Pose {
        a_a,
        a_b,
        r_ga,
        r_gb,
        r_cube,
    }
}

/// The gravity part of the potential with the vertical tilted by `t = (theta_t, eta_t,
/// phi_t)` (the crate's convention, [`crate::model::tilt`]: `up = R(t)^T e_z` has floor
/// components `(sin eta_t, -cos eta_t sin theta_t, cos eta_t cos theta_t)`), plus the fibres'
/// static pre-tension `T delta` with the nominal tensions `(m_a + m_b) g` and `m_b g` (linear
/// in delta: it cancels the weight along the fibres and leaves every second derivative alone).
/// The elastic energy `1/2 k q^2` of torsion and bouncing is added by the callers.
pub(super) fn gravity<T: Real>(c: &Consts<T>, q: &[T; 8], t: &[T; 3]) -> T {
    let p = pose(c, q);
    let ((st, ct), (se, ce)) = (t[0].sin_cos(), t[1].sin_cos());
    let up = [se, -(ce * st), ce * ct];
    c.g * (c.m_a * dot(up, p.r_ga) + c.m_b * dot(up, p.r_gb))
        + (c.m_a + c.m_b) * c.g * q[3]
        + c.m_b * c.g * q[7]
}

/// The axial vector `w` of a skew matrix `[w]x`.
pub(super) fn vee<T: Copy>(s: &M3<T>) -> V3<T> {
    [s[2][1], s[0][2], s[1][0]]
}

//! The parameters as [`Field`]s, one section at a time, in file order.

use super::{
    Allowed, Bouncing, Environment, Field, Inertia, Lengths, LossAngles, Masses, Torsion, Viscous,
};
use Allowed::*;

fn field(
    key: &'static str,
    value: f64,
    unit: &'static str,
    symbol: &'static str,
    allowed: Allowed,
) -> Field {
    Field {
        key,
        value,
        unit,
        symbol,
        allowed,
    }
}

impl Masses {
    /// The masses, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field("mass.m_a_kg", self.m_a_kg, "kg", "m_a", Positive),
            field("mass.m_b_kg", self.m_b_kg, "kg", "m_b", Positive),
        ]
    }
}

impl Inertia {
    /// The inertia tensors' entries, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field(
                "inertia.a11_kg_m2",
                self.a11_kg_m2,
                "kg m^2",
                "I^a_11",
                Positive,
            ),
            field(
                "inertia.a22_kg_m2",
                self.a22_kg_m2,
                "kg m^2",
                "I^a_22",
                Positive,
            ),
            field(
                "inertia.a33_kg_m2",
                self.a33_kg_m2,
                "kg m^2",
                "I^a_33",
                Positive,
            ),
            field(
                "inertia.a23_kg_m2",
                self.a23_kg_m2,
                "kg m^2",
                "I^a_23",
                Finite,
            ),
            field(
                "inertia.b11_kg_m2",
                self.b11_kg_m2,
                "kg m^2",
                "I^b_11",
                Positive,
            ),
            field(
                "inertia.b22_kg_m2",
                self.b22_kg_m2,
                "kg m^2",
                "I^b_22",
                Positive,
            ),
            field(
                "inertia.b33_kg_m2",
                self.b33_kg_m2,
                "kg m^2",
                "I^b_33",
                Positive,
            ),
        ]
    }
}

impl Torsion {
    /// The torsion constants, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field(
                "torsion.k_a_n_m_per_rad",
                self.k_a_n_m_per_rad,
                "N m/rad",
                "k_a",
                Positive,
            ),
            field(
                "torsion.k_b_n_m_per_rad",
                self.k_b_n_m_per_rad,
                "N m/rad",
                "k_b",
                Positive,
            ),
        ]
    }
}

impl Bouncing {
    /// The bouncing (vertical) spring constants, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field(
                "bouncing.kappa_a_n_per_m",
                self.kappa_a_n_per_m,
                "N/m",
                "kappa_e,a",
                Positive,
            ),
            field(
                "bouncing.kappa_b_n_per_m",
                self.kappa_b_n_per_m,
                "N/m",
                "kappa_e,b",
                Positive,
            ),
        ]
    }
}

impl Lengths {
    /// The lengths, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field("length.d_m", self.d_m, "m", "d", Length),
            field("length.h_c_m", self.h_c_m, "m", "h_c", LengthOrZero),
            field("length.z_m", self.z_m, "m", "Z", Length),
            field("length.z_a_m", self.z_a_m, "m", "Z_a", Length),
            field("length.z_b_m", self.z_b_m, "m", "Z_b", Length),
            field("length.h_m", self.h_m, "m", "h (assumption)", Length),
        ]
    }
}

impl Environment {
    /// The assumed environment, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field(
                "environment.g_m_per_s2",
                self.g_m_per_s2,
                "m/s^2",
                "g (assumption)",
                Positive,
            ),
            field(
                "environment.temperature_k",
                self.temperature_k,
                "K",
                "T (assumption)",
                Positive,
            ),
        ]
    }
}

impl LossAngles {
    /// The loss angles, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field(
                "loss.torsion_a_rad",
                self.torsion_a_rad,
                "rad",
                "phi_torsion,a",
                LossAngle,
            ),
            field(
                "loss.torsion_b_rad",
                self.torsion_b_rad,
                "rad",
                "phi_torsion,b",
                LossAngle,
            ),
            field(
                "loss.bouncing_a_rad",
                self.bouncing_a_rad,
                "rad",
                "phi_bouncing,a",
                LossAngle,
            ),
            field(
                "loss.bouncing_b_rad",
                self.bouncing_b_rad,
                "rad",
                "phi_bouncing,b",
                LossAngle,
            ),
            field(
                "loss.bending_a_rad",
                self.bending_a_rad,
                "rad",
                "phi_fibre,a (swing: / D_a)",
                LossAngle,
            ),
            field(
                "loss.bending_b_rad",
                self.bending_b_rad,
                "rad",
                "phi_fibre,b (swing: / D_b)",
                LossAngle,
            ),
            field("loss.dilution_a", self.dilution_a, "1", "D_a", AtLeastOne),
            field("loss.dilution_b", self.dilution_b, "1", "D_b", AtLeastOne),
        ]
    }
}

impl Viscous {
    /// The viscous damping coefficients, in file order.
    pub(super) fn fields(&self) -> Vec<Field> {
        vec![
            field(
                "viscous.torsion_a_n_m_s_per_rad",
                self.torsion_a_n_m_s_per_rad,
                "N m s/rad",
                "c_torsion,a",
                NonNegative,
            ),
            field(
                "viscous.torsion_b_n_m_s_per_rad",
                self.torsion_b_n_m_s_per_rad,
                "N m s/rad",
                "c_torsion,b",
                NonNegative,
            ),
            field(
                "viscous.bouncing_a_n_s_per_m",
                self.bouncing_a_n_s_per_m,
                "N s/m",
                "c_bouncing,a",
                NonNegative,
            ),
            field(
                "viscous.bouncing_b_n_s_per_m",
                self.bouncing_b_n_s_per_m,
                "N s/m",
                "c_bouncing,b",
                NonNegative,
            ),
            field(
                "viscous.swing_a_n_m_s_per_rad",
                self.swing_a_n_m_s_per_rad,
                "N m s/rad",
                "c_swing,a",
                NonNegative,
            ),
            field(
                "viscous.swing_b_n_m_s_per_rad",
                self.swing_b_n_m_s_per_rad,
                "N m s/rad",
                "c_swing,b",
                NonNegative,
            ),
        ]
    }
}

//! Names, units and index order of the generalized coordinates, observables and inputs.
//!
//! The order of [`Coord::ALL`] is the paper's q = (theta_a, eta_a, phi_a, delta_a, theta_b, eta_b,
//! phi_b, delta_b): every 8-vector and 8x8 matrix in the crate is indexed this way.

/// Generalized coordinates (section II.D). Angles of body `a` are relative to the enclosure;
/// angles of body `b` are relative to body `a`; `delta` are fibre elongations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Coord {
    /// Swing of the upper pendulum about x (rad).
    ThetaA,
    /// Swing of the upper pendulum about y (rad).
    EtaA,
    /// Torsion of the upper fibre (rad).
    PhiA,
    /// Elongation of the upper fibre (m).
    DeltaA,
    /// Swing of the test mass about x, relative to the crossbar (rad).
    ThetaB,
    /// Swing of the test mass about y, relative to the crossbar (rad).
    EtaB,
    /// Torsion of the lower fibre (rad).
    PhiB,
    /// Elongation of the lower fibre (m).
    DeltaB,
}

impl Coord {
    /// All coordinates in the crate's index order.
    pub const ALL: [Coord; 8] = [
        Coord::ThetaA,
        Coord::EtaA,
        Coord::PhiA,
        Coord::DeltaA,
        Coord::ThetaB,
        Coord::EtaB,
        Coord::PhiB,
        Coord::DeltaB,
    ];

    /// Index into 8-vectors.
    pub fn index(self) -> usize {
        self as usize
    }

    /// ASCII name as used in files.
    pub fn name(self) -> &'static str {
        [
            "theta_a", "eta_a", "phi_a", "delta_a", "theta_b", "eta_b", "phi_b", "delta_b",
        ][self.index()]
    }

    /// SI unit.
    pub fn unit(self) -> &'static str {
        match self {
            Coord::DeltaA | Coord::DeltaB => "m",
            _ => "rad",
        }
    }
}

/// Observables (section II.D): test-mass position X, Y, Z of the cube centre and attitude theta,
/// eta, phi, as read by the GRS in the enclosure frame, and the crossbar torsion phi_a read by the
/// autocollimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Observable {
    /// Cube centre along x (m).
    X,
    /// Cube centre along y (m).
    Y,
    /// Cube centre along z (m).
    Z,
    /// Test-mass rotation about x (rad).
    Theta,
    /// Test-mass rotation about y (rad).
    Eta,
    /// Test-mass rotation about z (rad).
    Phi,
    /// Crossbar rotation about z (rad).
    PhiA,
}

impl Observable {
    /// All observables in the crate's index order.
    pub const ALL: [Observable; 7] = [
        Observable::X,
        Observable::Y,
        Observable::Z,
        Observable::Theta,
        Observable::Eta,
        Observable::Phi,
        Observable::PhiA,
    ];

    /// Index into 7-vectors.
    pub fn index(self) -> usize {
        self as usize
    }

    /// ASCII name as used in files and on the command line.
    pub fn name(self) -> &'static str {
        ["X", "Y", "Z", "theta", "eta", "phi", "phi_a"][self.index()]
    }

    /// SI unit.
    pub fn unit(self) -> &'static str {
        match self {
            Observable::X | Observable::Y | Observable::Z => "m",
            _ => "rad",
        }
    }

    /// Looks an observable up by its name ([`Observable::name`], case-sensitive).
    pub fn from_name(name: &str) -> Option<Observable> {
        Observable::ALL.into_iter().find(|o| o.name() == name)
    }
}

/// Floor tilt angles. Sign convention: see [`crate::model::tilt`]. Positive `theta_t` makes the
/// test mass settle at +Y, positive `eta_t` at -X (the paper's stated quasi-static limits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum TiltAxis {
    /// Tilt about x (rad).
    ThetaT,
    /// Tilt about y (rad).
    EtaT,
    /// Rotation of the floor about the vertical (rad).
    PhiT,
}

impl TiltAxis {
    /// All tilt inputs in the crate's index order.
    pub const ALL: [TiltAxis; 3] = [TiltAxis::ThetaT, TiltAxis::EtaT, TiltAxis::PhiT];

    /// Index into 3-vectors.
    pub fn index(self) -> usize {
        self as usize
    }

    /// ASCII name as used in files and on the command line.
    pub fn name(self) -> &'static str {
        ["theta_t", "eta_t", "phi_t"][self.index()]
    }

    /// SI unit of the input.
    pub fn unit(self) -> &'static str {
        "rad"
    }
}

/// Floor translation: the displacement of the floor as a rigid body along the lab axes (m),
/// and with it of the pivot about which tilt is defined, the upper suspension point and the
/// sensor housing. Lab axes as the model's: the crossbar arm lies along y (the test mass at
/// `(0, -d, .)`), x is perpendicular to it (the test mass's X), z is up. See
/// [`crate::model::translation`] for the forcing and its low-frequency equivalence with tilt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum TranslationAxis {
    /// Displacement along x, perpendicular to the crossbar arm (m).
    XT,
    /// Displacement along y, along the crossbar arm (m).
    YT,
    /// Displacement along z, up (m).
    ZT,
}

impl TranslationAxis {
    /// All translation inputs in the crate's index order.
    pub const ALL: [TranslationAxis; 3] = [
        TranslationAxis::XT,
        TranslationAxis::YT,
        TranslationAxis::ZT,
    ];

    /// Index into 3-vectors (the lab axis: 0 for x, 1 for y, 2 for z).
    pub fn index(self) -> usize {
        self as usize
    }

    /// ASCII name as used in files and on the command line.
    pub fn name(self) -> &'static str {
        ["x_t", "y_t", "z_t"][self.index()]
    }

    /// SI unit of the input.
    pub fn unit(self) -> &'static str {
        "m"
    }
}

/// The 12 components of the external forces F_a, F_b (N, at the centres of mass) and torques
/// M_a, M_b (N m, about the centres of mass), inertial axes, in the order of [`ForceInput::ALL`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct ForceInput(usize);

impl ForceInput {
    /// All 12 components: F_a.x..z, F_b.x..z, M_a.x..z, M_b.x..z.
    pub const ALL: [ForceInput; 12] = [
        ForceInput(0),
        ForceInput(1),
        ForceInput(2),
        ForceInput(3),
        ForceInput(4),
        ForceInput(5),
        ForceInput(6),
        ForceInput(7),
        ForceInput(8),
        ForceInput(9),
        ForceInput(10),
        ForceInput(11),
    ];

    /// Index into 12-vectors.
    pub fn index(self) -> usize {
        self.0
    }

    /// ASCII name such as `F_b.x` or `M_a.z`.
    pub fn name(self) -> &'static str {
        [
            "F_a.x", "F_a.y", "F_a.z", "F_b.x", "F_b.y", "F_b.z", "M_a.x", "M_a.y", "M_a.z",
            "M_b.x", "M_b.y", "M_b.z",
        ][self.0]
    }

    /// SI unit: N for forces, N m for torques.
    pub fn unit(self) -> &'static str {
        if self.0 < 6 {
            "N"
        } else {
            "N m"
        }
    }

    /// Looks a component up by its name.
    pub fn from_name(name: &str) -> Option<ForceInput> {
        ForceInput::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// The two exactly decoupled blocks of the linear model: M, K and both forcings are block
/// diagonal in this split (the crossbar tensor has I^a_12 = I^a_13 = 0 and the test mass hangs in
/// the y-z symmetry plane).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Block {
    /// {theta_a, delta_a, theta_b, delta_b}: swinging along y and bouncing. Seen by Y, Z, theta;
    /// driven by theta_t and the floor translations y_t, z_t.
    SwingYBounce,
    /// {eta_a, phi_a, eta_b, phi_b}: swinging along x and torsion. Seen by X, eta, phi, phi_a;
    /// driven by eta_t, phi_t and the floor translation x_t.
    SwingXTorsion,
}

impl Block {
    /// Both blocks.
    pub const ALL: [Block; 2] = [Block::SwingYBounce, Block::SwingXTorsion];

    /// The coordinates of the block, in crate index order.
    pub fn coords(self) -> [Coord; 4] {
        match self {
            Block::SwingYBounce => [Coord::ThetaA, Coord::DeltaA, Coord::ThetaB, Coord::DeltaB],
            Block::SwingXTorsion => [Coord::EtaA, Coord::PhiA, Coord::EtaB, Coord::PhiB],
        }
    }

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Block::SwingYBounce => "swing-y+bounce",
            Block::SwingXTorsion => "swing-x+torsion",
        }
    }
}

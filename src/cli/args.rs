//! Value types shared by several subcommands: the method, averaging and output-format
//! choices, the `LO:HI` range and the `--readout OBS=ASD` item.

use anyhow::{anyhow, Result};
use clap::{Args, ValueEnum};
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::input::{AxisMap, ReadOptions};
use tiltnoise_core::model::Observable;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options::parse_keyed_items;
use tiltnoise_core::repeats::{list_entries, refuse_repeats};
use tiltnoise_core::tf::Method;

/// Welch averaging.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AverageArg {
    Mean,
    Median,
}

/// Output format on the terminal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Table,
    Json,
}

/// Evaluation method of the transfer functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Smallest model and cheapest method meeting 1e-9 relative on the grid's band, verified
    /// against the double-double reference (see --explain).
    Auto,
    /// Per-frequency LU of the full 8x8 model (the oracle of the fast methods).
    Direct,
    /// Per-frequency LU of the decoupled 4x4 blocks the request needs.
    Block,
    /// Block LU in absolute angles with the static / mass-line split: full relative accuracy.
    Split,
    /// Pole-zero product form per entry, built once in double-double: accurate and fastest.
    Polezero,
    /// Modal superposition (fast; loses accuracy where modal terms cancel).
    Modal,
    /// First-order state space as python-control and scipy.signal evaluate it (comparison;
    /// loses accuracy where the tilt forcing cancels).
    Statespace,
    /// The 2-DoF torsional model of section IV.C (no tilt inputs).
    Torsion2,
}

/// What the floor's motion is per unit of, in `tf`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PerArg {
    /// Per unit displacement: rad, m (the model's inputs).
    Displacement,
    /// Per unit velocity: rad/s, m/s.
    Velocity,
    /// Per unit acceleration: rad/s^2, m/s^2.
    Acceleration,
}

impl PerArg {
    /// The library's quantity.
    pub fn quantity(self) -> GroundQuantity {
        match self {
            PerArg::Displacement => GroundQuantity::Displacement,
            PerArg::Velocity => GroundQuantity::Velocity,
            PerArg::Acceleration => GroundQuantity::Acceleration,
        }
    }
}

impl MethodArg {
    /// The fixed method, or `None` for `auto`.
    pub fn fixed(self) -> Option<Method> {
        match self {
            MethodArg::Auto => None,
            MethodArg::Direct => Some(Method::Direct),
            MethodArg::Block => Some(Method::Block),
            MethodArg::Split => Some(Method::Split),
            MethodArg::Polezero => Some(Method::PoleZero),
            MethodArg::Modal => Some(Method::Modal),
            MethodArg::Statespace => Some(Method::StateSpace),
            MethodArg::Torsion2 => Some(Method::Torsion2),
        }
    }
}

/// A default value as help prints it, in scientific notation (`1e-9`, not `0.000000001`).
pub fn scientific(x: f64) -> String {
    format!("{x:e}")
}

/// One `--readout OBS=ASD` item (also used by `simulate`): the observable and its white
/// readout noise, one-sided ASD in the observable's unit/sqrt(Hz), finite and >= 0.
pub fn parse_readout_item(item: &str) -> Result<(Observable, f64)> {
    Ok(tiltnoise_core::options::parse_readout_item(
        OptionKey::READOUT,
        item,
    )?)
}

/// What a record's channels are, for the commands that read translation channels too: their
/// units, and which sensors are declared other than the default (see docs/input_formats.md).
#[derive(Debug, Clone, Default, Args)]
pub struct ChannelArgs {
    /// Unit of a source channel, CHANNEL=UNIT (repeatable), for files that do not state it
    /// (miniSEED, CSV without `# units:`): rad, urad, nrad (tilt angle), rad/s (rate), or m,
    /// m/s, m/s^2 and their prefixed forms (floor translation: displacement, velocity,
    /// acceleration); translation channels need one. Must agree where the file states a unit.
    #[arg(long, value_name = "CHANNEL=UNIT")]
    pub units: Vec<String>,
    /// Translation channels (seismometers, accelerometers) whose tilt part is removed already
    /// (repeatable or comma-separated): by default an inertial sensor, which reads
    /// a_x + g eta_t, is corrected with the record's tilt of its axis.
    #[arg(long, value_name = "CHANNEL")]
    pub corrected: Vec<String>,
    /// Tilt channels read by a pendulum tiltmeter, which senses eta_t + a_x/g (repeatable or
    /// comma-separated): corrected with the record's translation of its axis, which must then
    /// be free of tilt (--corrected).
    #[arg(long, value_name = "CHANNEL")]
    pub pendulum_tiltmeter: Vec<String>,
}

/// The channel names of a repeatable, comma-separated option, each once.
fn channel_names(option: OptionKey, items: &[String]) -> Result<Vec<String>> {
    let names = list_entries(items);
    refuse_repeats(option, "channel", &names, |n| n.to_string())?;
    Ok(names.into_iter().map(str::to_string).collect())
}

/// How to read a record of the floor's motion from the `--axes MAP`, `--quantity angle|rate`,
/// `--gaps reject|interpolate` and `--scale CHANNEL=FACTOR` options and the channel options
/// `--units`, `--corrected`, `--pendulum-tiltmeter` (each optional; gaps default to reject).
/// The one reading of these options for every command that reads tilt.
pub fn read_options(
    axes: Option<&str>,
    quantity: Option<&str>,
    gaps: Option<&str>,
    scale: &[String],
    channels: &ChannelArgs,
) -> Result<ReadOptions> {
    Ok(ReadOptions {
        axis_map: axes.map(AxisMap::parse).transpose()?,
        quantity: quantity
            .map(str::parse)
            .transpose()
            .map_err(|e: String| anyhow!("--quantity: {e}"))?,
        gaps: gaps
            .unwrap_or("reject")
            .parse()
            .map_err(|e: String| anyhow!("--gaps: {e}"))?,
        scale: parse_keyed_items(OptionKey::SCALE, "channel", scale)?,
        units: parse_keyed_items(OptionKey::UNITS, "channel", &channels.units)?,
        corrected: channel_names(OptionKey::CORRECTED, &channels.corrected)?,
        pendulum: channel_names(OptionKey::PENDULUM_TILTMETER, &channels.pendulum_tiltmeter)?,
    })
}

/// [`read_options`] without the channel options, for the commands that read tilt channels
/// only.
pub fn tilt_read_options(
    axes: Option<&str>,
    quantity: Option<&str>,
    gaps: Option<&str>,
    scale: &[String],
) -> Result<ReadOptions> {
    read_options(axes, quantity, gaps, scale, &ChannelArgs::default())
}

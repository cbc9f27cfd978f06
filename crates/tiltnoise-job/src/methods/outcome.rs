//! The methods compared: a table on the terminal, the JSON report, the chart of time per
//! point against worst error.

use crate::error::JobError;
use crate::figures::View;
use crate::outcome::{output_kind, Outcome, Provenance};
use serde::Serialize;
use std::path::Path;
use tiltnoise_core::methods::MethodRow;
use tiltnoise_core::model::{Input, Request};
use tiltnoise_core::tf::planner::NoChoice;
use tiltnoise_core::tf::Method;
use tiltnoise_io::{OutputKind, Staging};
use tiltnoise_plot::methods_figure::{methods_figure, MethodPoint};

/// Every method measured, and `auto`'s pick at the default tolerance.
pub struct MethodsOutcome {
    /// The matrix measured.
    pub request: Request,
    /// The grid (Hz).
    pub grid_hz: Vec<f64>,
    /// One row per method of [`Method::ALL`], in that order.
    pub rows: Vec<MethodRow>,
    /// What `auto` picks on the grid's band at [`MethodsOutcome::target_rel_err`], or why none.
    pub auto: Result<Method, NoChoice>,
    /// The tolerance `auto` is asked for.
    pub target_rel_err: f64,
    /// The grid as the user gave it.
    pub grid_spec: String,
    pub(crate) view: View,
    pub(crate) provenance: Provenance,
}

impl MethodsOutcome {
    /// `7x3 tilt matrix`, `7x6 ground matrix`, or the inputs named: what the table measures.
    pub fn matrix_label(&self) -> String {
        let request = &self.request;
        let size = format!("{}x{}", request.outputs.len(), request.inputs.len());
        let groups = [
            ("tilt", Input::all_tilts()),
            ("translation", Input::all_translations()),
            ("ground", Input::all_ground()),
        ];
        match groups.iter().find(|(_, inputs)| *inputs == request.inputs) {
            Some((name, _)) => format!("{size} {name} matrix"),
            None => {
                let names: Vec<&str> = request.inputs.iter().map(|i| i.name()).collect();
                format!("{size} matrix from {}", names.join(", "))
            }
        }
    }

    /// The grid as the chart's title names it: `400 points, 1e-5 to 1e2 Hz`.
    pub fn grid_label(&self) -> String {
        let (lo, hi) = match (self.grid_hz.first(), self.grid_hz.last()) {
            (Some(lo), Some(hi)) => (*lo, *hi),
            _ => (f64::NAN, f64::NAN),
        };
        format!("{} points, {lo:e} to {hi:e} Hz", self.grid_hz.len())
    }

    /// `auto`'s pick as the table and the JSON name it: the method, or `none (why)`.
    pub fn auto_text(&self) -> String {
        match &self.auto {
            Ok(m) => m.name().to_string(),
            Err(refusal) => format!("none ({refusal})"),
        }
    }
}

/// One method's row of the JSON report (keys in alphabetical order, as documented).
#[derive(Serialize)]
struct MethodJson {
    exact_zeros: Option<bool>,
    max_rel_err: Option<f64>,
    name: &'static str,
    ns_per_point: Option<f64>,
    unusable: Option<String>,
    worst_entry: Option<String>,
    worst_freq_hz: Option<f64>,
}

/// The JSON report of the comparison (keys in alphabetical order).
#[derive(Serialize)]
struct MethodsJson<'a> {
    auto: String,
    grid: &'a str,
    methods: Vec<MethodJson>,
    target_rel_err: f64,
}

impl Outcome for MethodsOutcome {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// The chart: `.png`, `.svg`.
    fn output_kinds(&self) -> &'static [OutputKind] {
        &[OutputKind::Png, OutputKind::Svg]
    }

    /// Saves the chart of the comparison (time per point against worst error, one point per
    /// usable method, the target error marked), drawn in the request's view; the same for
    /// every front end.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        output_kind(path, self.output_kinds())?;
        let points: Vec<MethodPoint> = self
            .rows
            .iter()
            .filter_map(|r| {
                Some((
                    r.method.name().to_string(),
                    r.ns_per_point?,
                    r.worst.as_ref()?.0,
                ))
            })
            .collect();
        let title = format!(
            "Speed against accuracy, {}, {}",
            self.matrix_label(),
            self.grid_label()
        );
        Ok(crate::save_image(stage, path, |format| {
            methods_figure(&points, self.target_rel_err, &title, &self.view, format)
        })?)
    }

    /// `methods --format json`: `auto`, `grid` (as given), `methods` (one object per method:
    /// `name`, `max_rel_err`, `worst_entry`, `worst_freq_hz`, `ns_per_point`, `exact_zeros`,
    /// `unusable`, `null` where a value does not apply) and `target_rel_err`.
    fn json(&self) -> serde_json::Value {
        let methods = self
            .rows
            .iter()
            .map(|r| MethodJson {
                name: r.method.name(),
                max_rel_err: r.worst.as_ref().map(|w| w.0),
                worst_entry: r.worst.as_ref().map(|w| w.1.clone()),
                worst_freq_hz: r.worst.as_ref().map(|w| w.2),
                ns_per_point: r.ns_per_point,
                exact_zeros: r.exact_zeros,
                unusable: r.unusable.clone(),
            })
            .collect();
        serde_json::to_value(MethodsJson {
            auto: self.auto_text(),
            target_rel_err: self.target_rel_err,
            grid: &self.grid_spec,
            methods,
        })
        .expect("JSON of plain data")
    }
}

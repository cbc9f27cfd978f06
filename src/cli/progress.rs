//! The command line's [`Progress`]: a bar on standard error, drawn only when it is a terminal
//! and the work is long enough to wait for. Every command's job reports through it.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::OnceLock;
use tiltnoise_job::Progress;

/// A progress bar of `unit`s (samples, draws, frequencies), shown from the first report when
/// standard error is a terminal and the total is at least `worth_a_bar` units.
pub(crate) struct Bar {
    unit: &'static str,
    worth_a_bar: u64,
    bar: OnceLock<Option<ProgressBar>>,
}

impl Bar {
    /// A bar of `unit`s worth drawing from `worth_a_bar` units.
    pub(crate) fn new(unit: &'static str, worth_a_bar: u64) -> Self {
        Self {
            unit,
            worth_a_bar,
            bar: OnceLock::new(),
        }
    }

    fn bar(&self, total: u64) -> Option<&ProgressBar> {
        self.bar
            .get_or_init(|| {
                (total >= self.worth_a_bar && std::io::stderr().is_terminal()).then(|| {
                    let bar = ProgressBar::new(total);
                    let template = format!(
                        "{{spinner}} {{wide_bar}} {{pos}}/{{len}} {} ({{percent}}%, eta {{eta}})",
                        self.unit
                    );
                    bar.set_style(ProgressStyle::with_template(&template).expect("valid template"));
                    bar
                })
            })
            .as_ref()
    }
}

impl Progress for Bar {
    fn report(&self, done: u64, total: u64) {
        if let Some(bar) = self.bar(total) {
            bar.set_length(total);
            bar.set_position(done);
        }
    }

    fn finish(&self) {
        if let Some(Some(bar)) = self.bar.get() {
            bar.finish_and_clear();
        }
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.finish();
    }
}

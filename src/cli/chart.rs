//! Saving the charts of `formation plot` at the run's `--dpi` (set once by the dispatcher in
//! `plot.rs`, read by each chart's own command file).

use formation::Result;

/// The `--dpi` of this run.
static DPI: std::sync::OnceLock<f64> = std::sync::OnceLock::new();

/// Sets this run's `--dpi` (the first call wins).
pub fn set_dpi(dpi: f64) {
    let _ = DPI.set(dpi);
}

/// Saves `chart` to `path` (PNG or SVG by its name) at the run's `--dpi`.
pub fn save<C: formation::plot::Chart>(chart: &C, path: &std::path::Path) -> Result<()> {
    formation::plot::save_at(chart, path, DPI.get().copied())
}

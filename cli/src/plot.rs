//! SVG plotting for the host CLI.
//!
//! A small, opinionated layer over [`plotters`] that turns a [`Figure`] (a
//! handful of [`Series`] plus optional horizontal reference lines) into an SVG
//! file. Only the SVG backend is used: text is emitted as SVG `<text>`
//! elements, so no system fonts are needed.
//!
//! * [`write_svg`] writes one figure on a 900×600 canvas.
//! * [`write_svg_grid`] writes several small panels (e.g. three belt variants
//!   side by side) into one SVG.
//!
//! Axis ranges are derived from the finite data with 5 % padding. With
//! [`Figure::equal_aspect`] one data unit has the same length on both axes,
//! which is what belt shapes in millimetres need.
//!
//! Files are written atomically: the SVG is rendered in memory, written to a
//! temporary file in the target's directory and renamed into place, so an
//! interrupted run never leaves a truncated plot behind.

use std::fmt;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Canvas size of a single figure written by [`write_svg`], in pixels.
const FIGURE_SIZE: (u32, u32) = (900, 600);
/// Size of one panel in [`write_svg_grid`], in pixels.
const PANEL_SIZE: (u32, u32) = (480, 360);
/// Height of the title band above the panels in [`write_svg_grid`].
const GRID_TITLE_HEIGHT: u32 = 40;
/// Largest canvas side accepted, to keep a runaway panel count from
/// producing an absurd file (or overflowing pixel arithmetic).
const MAX_CANVAS_SIDE: u32 = 20_000;
/// Relative padding added on each side of the data range.
const PAD_FRACTION: f64 = 0.05;

/// Fixed colour palette (Tableau 10 without grey/olive); cycles when a
/// figure has more lines than colours.
const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),  // blue
    RGBColor(255, 127, 14),  // orange
    RGBColor(44, 160, 44),   // green
    RGBColor(214, 39, 40),   // red
    RGBColor(148, 103, 189), // purple
    RGBColor(140, 86, 75),   // brown
    RGBColor(227, 119, 194), // pink
    RGBColor(23, 190, 207),  // cyan
];

/// One data series of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text. An empty label keeps the series out of the legend.
    pub label: String,
    /// Data points `(x, y)` in drawing order. Points with a non-finite
    /// coordinate are ignored (lines are broken there rather than bridged).
    pub points: Vec<(f64, f64)>,
    /// How the points are drawn.
    pub kind: SeriesKind,
}

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesKind {
    /// Solid line through the points.
    Line,
    /// Dashed line through the points (e.g. a model prediction or a
    /// reference curve).
    Dashed,
    /// A small filled circle at every point (e.g. measured samples).
    Markers,
}

/// A horizontal reference line across the whole plot, e.g. a measured
/// settled height.
#[derive(Debug, Clone, PartialEq)]
pub struct HLine {
    /// Legend text. An empty label keeps the line out of the legend.
    pub label: String,
    /// Height of the line in data units. A non-finite value is ignored.
    pub y: f64,
}

/// Everything needed to draw one chart.
#[derive(Debug, Clone, Copy)]
pub struct Figure<'a> {
    /// Chart title (empty for none).
    pub title: &'a str,
    /// Description of the x axis, including units.
    pub x_label: &'a str,
    /// Description of the y axis, including units.
    pub y_label: &'a str,
    /// The data series, drawn in order; each gets the next palette colour.
    pub series: &'a [Series],
    /// Horizontal reference lines, drawn after the series; they take the
    /// palette colours following those of the series.
    pub hlines: &'a [HLine],
    /// If true, one data unit has the same on-screen length on both axes
    /// (the shorter range is widened around its centre). Use it for shapes,
    /// e.g. a belt outline in mm.
    pub equal_aspect: bool,
}

/// Why a plot could not be written. Every variant names the target file.
#[derive(Debug)]
#[non_exhaustive]
pub enum PlotError {
    /// A figure has no finite data point (series points or hlines) to plot.
    NoData {
        /// The SVG file that was to be written.
        path: PathBuf,
        /// Title of the offending figure (may be empty).
        figure: String,
    },
    /// The request itself is unusable (no panels, zero columns, a data range
    /// too large for `f64`, a path without a file name, ...).
    InvalidInput {
        /// The SVG file that was to be written.
        path: PathBuf,
        /// What is wrong with the input.
        reason: String,
    },
    /// The plotting library reported an error while rendering.
    Render {
        /// The SVG file that was to be written.
        path: PathBuf,
        /// The error reported by `plotters`.
        reason: String,
    },
    /// Creating the directory, writing the temporary file or renaming it
    /// into place failed.
    Io {
        /// The SVG file that was to be written.
        path: PathBuf,
        /// What was being done when the error occurred.
        action: &'static str,
        /// The underlying I/O error.
        source: io::Error,
    },
}

impl PlotError {
    /// The SVG file the failed operation was writing.
    pub fn path(&self) -> &Path {
        match self {
            PlotError::NoData { path, .. }
            | PlotError::InvalidInput { path, .. }
            | PlotError::Render { path, .. }
            | PlotError::Io { path, .. } => path,
        }
    }
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cannot write plot {}: ", self.path().display())?;
        match self {
            PlotError::NoData { figure, .. } if figure.is_empty() => {
                write!(f, "figure has no finite data points")
            }
            PlotError::NoData { figure, .. } => {
                write!(f, "figure \"{figure}\" has no finite data points")
            }
            PlotError::InvalidInput { reason, .. } => write!(f, "invalid input: {reason}"),
            PlotError::Render { reason, .. } => write!(f, "rendering failed: {reason}"),
            PlotError::Io { action, source, .. } => write!(f, "{action}: {source}"),
        }
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PlotError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Writes `fig` as a 900×600 SVG to `path`.
///
/// The parent directory is created if missing, and the file is replaced
/// atomically (temporary file in the same directory, then rename).
///
/// # Errors
/// [`PlotError::NoData`] if the figure has no finite point,
/// [`PlotError::InvalidInput`] for unusable data ranges or paths,
/// [`PlotError::Render`] / [`PlotError::Io`] if rendering or writing fails.
pub fn write_svg(path: &Path, fig: &Figure) -> Result<(), PlotError> {
    let svg = render_figure(path, fig)?.0;
    write_atomically(path, svg.as_bytes())
}

/// Writes several figures as a grid of small panels (480×360 each) into one
/// SVG at `path`, with `title` above the grid.
///
/// Panels are laid out row by row, `columns` per row (fewer if there are
/// fewer panels). Each panel keeps its own title, axis labels, legend and
/// `equal_aspect` setting. File handling is as in [`write_svg`].
///
/// # Errors
/// [`PlotError::InvalidInput`] if `panels` is empty, `columns` is zero or the
/// grid would be unreasonably large; otherwise as for [`write_svg`] (a panel
/// without finite data is a [`PlotError::NoData`]).
pub fn write_svg_grid(
    path: &Path,
    title: &str,
    panels: &[Figure],
    columns: usize,
) -> Result<(), PlotError> {
    let svg = render_grid(path, title, panels, columns)?.0;
    write_atomically(path, svg.as_bytes())
}

// ---------------------------------------------------------------------------
// Rendering
// ---------------------------------------------------------------------------

/// Final axis ranges and plotting-area size of one rendered panel (used by
/// the tests to check the equal-aspect scaling).
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(test), allow(dead_code))]
struct PanelLayout {
    x: (f64, f64),
    y: (f64, f64),
    plot_px: (u32, u32),
}

/// Font sizes and label-area sizes for one chart.
struct Look {
    title_font: u32,
    desc_font: u32,
    tick_font: u32,
    legend_font: u32,
    margin: u32,
    x_label_area: u32,
    y_label_area: u32,
}

const FULL_LOOK: Look = Look {
    title_font: 26,
    desc_font: 18,
    tick_font: 15,
    legend_font: 16,
    margin: 12,
    x_label_area: 48,
    y_label_area: 72,
};

const PANEL_LOOK: Look = Look {
    title_font: 20,
    desc_font: 15,
    tick_font: 13,
    legend_font: 13,
    margin: 8,
    x_label_area: 40,
    y_label_area: 60,
};

/// Renders a single figure to an SVG string.
fn render_figure(path: &Path, fig: &Figure) -> Result<(String, PanelLayout), PlotError> {
    let extents = data_extents(path, fig)?;
    let mut svg = String::new();
    let layout = {
        let root = SVGBackend::with_string(&mut svg, FIGURE_SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| render_err(path, e))?;
        let layout = draw_figure(path, &root, fig, &extents, &FULL_LOOK)?;
        root.present().map_err(|e| render_err(path, e))?;
        layout
    };
    Ok((svg, layout))
}

/// Renders a grid of panels to an SVG string.
fn render_grid(
    path: &Path,
    title: &str,
    panels: &[Figure],
    columns: usize,
) -> Result<(String, Vec<PanelLayout>), PlotError> {
    if panels.is_empty() {
        return Err(invalid(path, "a grid needs at least one panel"));
    }
    if columns == 0 {
        return Err(invalid(path, "a grid needs at least one column"));
    }
    let columns = columns.min(panels.len());
    let rows = panels.len().div_ceil(columns);
    let canvas = grid_canvas_size(rows, columns)
        .ok_or_else(|| invalid(path, format!("a {rows}x{columns} grid is too large")))?;

    // Validate every panel before drawing anything.
    let extents = panels
        .iter()
        .map(|fig| data_extents(path, fig))
        .collect::<Result<Vec<_>, _>>()?;

    let mut svg = String::new();
    let layouts = {
        let root = SVGBackend::with_string(&mut svg, canvas).into_drawing_area();
        root.fill(&WHITE).map_err(|e| render_err(path, e))?;
        let (top, body) = root.split_vertically(GRID_TITLE_HEIGHT);
        if !title.is_empty() {
            let style = TextStyle::from(("sans-serif", 26).into_font())
                .pos(Pos::new(HPos::Center, VPos::Center));
            let (w, h) = top.dim_in_pixel();
            top.draw_text(title, &style, (w as i32 / 2, h as i32 / 2))
                .map_err(|e| render_err(path, e))?;
        }
        let cells = body.split_evenly((rows, columns));
        let mut layouts = Vec::with_capacity(panels.len());
        for ((cell, fig), ext) in cells.iter().zip(panels).zip(&extents) {
            layouts.push(draw_figure(path, cell, fig, ext, &PANEL_LOOK)?);
        }
        root.present().map_err(|e| render_err(path, e))?;
        layouts
    };
    Ok((svg, layouts))
}

/// Canvas size for a `rows`×`columns` grid, or `None` if it is too large.
fn grid_canvas_size(rows: usize, columns: usize) -> Option<(u32, u32)> {
    let rows = u32::try_from(rows).ok()?;
    let columns = u32::try_from(columns).ok()?;
    let w = columns.checked_mul(PANEL_SIZE.0)?;
    let h = rows
        .checked_mul(PANEL_SIZE.1)?
        .checked_add(GRID_TITLE_HEIGHT)?;
    (w <= MAX_CANVAS_SIDE && h <= MAX_CANVAS_SIDE).then_some((w, h))
}

/// Finite data extents of a figure: `(x_min, x_max)` (if any series point is
/// finite) and `(y_min, y_max)`.
struct Extents {
    x: Option<(f64, f64)>,
    y: (f64, f64),
}

fn data_extents(path: &Path, fig: &Figure) -> Result<Extents, PlotError> {
    let mut x: Option<(f64, f64)> = None;
    let mut y: Option<(f64, f64)> = None;
    let widen = |r: &mut Option<(f64, f64)>, v: f64| {
        *r = Some(match *r {
            None => (v, v),
            Some((lo, hi)) => (lo.min(v), hi.max(v)),
        });
    };
    for s in fig.series {
        for &(px, py) in s.points.iter().filter(|p| is_finite_point(**p)) {
            widen(&mut x, px);
            widen(&mut y, py);
        }
    }
    for h in fig.hlines.iter().filter(|h| h.y.is_finite()) {
        widen(&mut y, h.y);
    }
    match y {
        Some(y) => Ok(Extents { x, y }),
        None => Err(PlotError::NoData {
            path: path.to_path_buf(),
            figure: fig.title.to_string(),
        }),
    }
}

fn is_finite_point((x, y): (f64, f64)) -> bool {
    x.is_finite() && y.is_finite()
}

/// Pads a data range by [`PAD_FRACTION`] on each side; a (near-)degenerate
/// range gets a sensible width around its value. `None` if the result is not
/// representable.
fn padded_range(lo: f64, hi: f64) -> Option<(f64, f64)> {
    // Below this everything is treated as zero: tick generation in plotters
    // misbehaves on spans near the subnormal range.
    const TINY: f64 = 1e-150;
    let span = hi - lo;
    let mag = lo.abs().max(hi.abs());
    let (a, b) = if !span.is_finite() {
        return None;
    } else if span <= mag * 1e-9 || span < TINY {
        let centre = lo + span / 2.0;
        let half = if mag >= TINY { mag * PAD_FRACTION } else { 1.0 };
        (centre - half, centre + half)
    } else {
        let pad = span * PAD_FRACTION;
        (lo - pad, hi + pad)
    };
    (a.is_finite() && b.is_finite() && (b - a).is_finite() && a < b).then_some((a, b))
}

/// Widens the shorter of two ranges (around its centre) so that one data
/// unit maps to the same number of pixels on both axes of a `w`×`h` plot.
fn equalize_ranges(
    x: (f64, f64),
    y: (f64, f64),
    (w, h): (u32, u32),
) -> Option<((f64, f64), (f64, f64))> {
    if w == 0 || h == 0 {
        return Some((x, y));
    }
    let (w, h) = (f64::from(w), f64::from(h));
    let units_per_px = ((x.1 - x.0) / w).max((y.1 - y.0) / h);
    let stretch = |(lo, hi): (f64, f64), px: f64| {
        let half = units_per_px * px / 2.0;
        let centre = lo + (hi - lo) / 2.0;
        (centre - half, centre + half)
    };
    let (x, y) = (stretch(x, w), stretch(y, h));
    let ok = |(lo, hi): (f64, f64)| lo.is_finite() && hi.is_finite() && lo < hi;
    (ok(x) && ok(y)).then_some((x, y))
}

fn palette(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Splits `points` into runs of consecutive finite points.
fn finite_runs(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut current = Vec::new();
    for &p in points {
        if is_finite_point(p) {
            current.push(p);
        } else if !current.is_empty() {
            runs.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs
}

/// Tick label: plain decimal for ordinary magnitudes, scientific otherwise.
fn tick_label(v: &f64) -> String {
    let v = *v;
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            v.to_string()
        };
    }
    let a = v.abs();
    if (1e-4..1e7).contains(&a) {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    } else {
        format!("{v:.3e}")
    }
}

/// Picks the plot corner with the fewest data points for the legend.
fn legend_corner(fig: &Figure, x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    const FRAC: f64 = 0.35;
    let (xw, yh) = (x.1 - x.0, y.1 - y.0);
    // Is `v` inside the corner band at the high (`hi`) or low end of `range`?
    let in_band = |v: f64, range: (f64, f64), width: f64, hi: bool| {
        if hi {
            v >= range.1 - FRAC * width
        } else {
            v <= range.0 + FRAC * width
        }
    };
    // (position, right side?, top side?); preference order on ties.
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (pos, right, top) in corners {
        let inside = |px: f64, py: f64| in_band(px, x, xw, right) && in_band(py, y, yh, top);
        let mut n = 0usize;
        for s in fig.series {
            n += s
                .points
                .iter()
                .filter(|p| is_finite_point(**p) && inside(p.0, p.1))
                .count();
        }
        for h in fig.hlines.iter().filter(|h| h.y.is_finite()) {
            // An hline crosses the whole width; weigh it like a few points
            // so the legend avoids covering it.
            if in_band(h.y, y, yh, top) {
                n += 5;
            }
        }
        if n < best.0 {
            best = (n, pos);
        }
    }
    best.1
}

/// Draws one figure into `area`, returning the final axis layout.
fn draw_figure(
    path: &Path,
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    fig: &Figure,
    extents: &Extents,
    look: &Look,
) -> Result<PanelLayout, PlotError> {
    let too_large = || invalid(path, "data range too large to plot");
    let x_data = extents.x.unwrap_or((0.0, 1.0));
    let x_range = padded_range(x_data.0, x_data.1).ok_or_else(too_large)?;
    let y_range = padded_range(extents.y.0, extents.y.1).ok_or_else(too_large)?;

    let area = if fig.title.is_empty() {
        area.clone()
    } else {
        area.titled(fig.title, ("sans-serif", look.title_font))
            .map_err(|e| render_err(path, e))?
    };

    let builder = |area| {
        let mut b = ChartBuilder::on(area);
        b.margin(look.margin)
            .x_label_area_size(look.x_label_area)
            .y_label_area_size(look.y_label_area);
        b
    };

    let (x_range, y_range) = if fig.equal_aspect {
        // Building a chart draws nothing (there is no caption), so a probe
        // with dummy ranges tells the exact plotting-area size.
        let probe = builder(&area)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)
            .map_err(|e| render_err(path, e))?;
        let dims = probe.plotting_area().dim_in_pixel();
        equalize_ranges(x_range, y_range, dims).ok_or_else(too_large)?
    } else {
        (x_range, y_range)
    };

    let mut chart = builder(&area)
        .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
        .map_err(|e| render_err(path, e))?;
    let plot_px = chart.plotting_area().dim_in_pixel();

    chart
        .configure_mesh()
        .x_desc(fig.x_label)
        .y_desc(fig.y_label)
        .axis_desc_style(("sans-serif", look.desc_font))
        .label_style(("sans-serif", look.tick_font))
        .x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
        .bold_line_style(RGBColor(218, 218, 218))
        .light_line_style(RGBColor(240, 240, 240))
        .draw()
        .map_err(|e| render_err(path, e))?;

    let mut labelled = 0usize;
    for (i, s) in fig.series.iter().enumerate() {
        let colour = palette(i);
        // Always issue at least one draw call so the legend entry exists even
        // if this particular series has no finite point.
        let mut runs = finite_runs(&s.points);
        if runs.is_empty() {
            runs.push(Vec::new());
        }
        for (k, run) in runs.into_iter().enumerate() {
            let anno = match s.kind {
                SeriesKind::Line => chart.draw_series(LineSeries::new(run, colour.stroke_width(2))),
                SeriesKind::Dashed => {
                    chart.draw_series(DashedLineSeries::new(run, 10, 6, colour.stroke_width(2)))
                }
                SeriesKind::Markers => {
                    chart.draw_series(run.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                }
            }
            .map_err(|e| render_err(path, e))?;
            if k == 0 && !s.label.is_empty() {
                labelled += 1;
                anno.label(s.label.as_str());
                match s.kind {
                    SeriesKind::Line => anno.legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                    }),
                    SeriesKind::Dashed => anno.legend(move |(x, y)| {
                        DashedPathElement::new(
                            vec![(x, y), (x + 20, y)],
                            6,
                            4,
                            colour.stroke_width(2),
                        )
                    }),
                    SeriesKind::Markers => {
                        anno.legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.filled()))
                    }
                };
            }
        }
    }

    for (j, h) in fig.hlines.iter().enumerate() {
        if !h.y.is_finite() {
            continue;
        }
        let colour = palette(fig.series.len() + j);
        let anno = chart
            .draw_series(DashedLineSeries::new(
                [(x_range.0, h.y), (x_range.1, h.y)],
                4,
                4,
                colour.stroke_width(1),
            ))
            .map_err(|e| render_err(path, e))?;
        if !h.label.is_empty() {
            labelled += 1;
            anno.label(h.label.as_str()).legend(move |(x, y)| {
                DashedPathElement::new(vec![(x, y), (x + 20, y)], 4, 4, colour.stroke_width(1))
            });
        }
    }

    if labelled > 0 {
        chart
            .configure_series_labels()
            .position(legend_corner(fig, x_range, y_range))
            .label_font(("sans-serif", look.legend_font))
            .background_style(WHITE)
            .border_style(RGBColor(160, 160, 160))
            .margin(8)
            .legend_area_size(26)
            .draw()
            .map_err(|e| render_err(path, e))?;
    }

    Ok(PanelLayout {
        x: x_range,
        y: y_range,
        plot_px,
    })
}

fn render_err(path: &Path, e: impl fmt::Display) -> PlotError {
    PlotError::Render {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

fn invalid(path: &Path, reason: impl Into<String>) -> PlotError {
    PlotError::InvalidInput {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

// ---------------------------------------------------------------------------
// Atomic file output
// ---------------------------------------------------------------------------

/// Writes `bytes` to `path` atomically (the host library's
/// [`trackbelt_host::atomic::write_atomic`]), creating the directory if
/// needed.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    if path.file_name().is_none() {
        return Err(invalid(path, "the path has no file name"));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    fs::create_dir_all(dir).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        action: "cannot create the directory",
        source,
    })?;
    trackbelt_host::atomic::write_atomic(path, bytes).map_err(|e| match e {
        trackbelt_host::Error::Io { action, source, .. } => PlotError::Io {
            path: path.to_path_buf(),
            action,
            source,
        },
        e => invalid(path, e.to_string()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    /// A fresh, unique directory under the system temp dir.
    fn temp_dir(tag: &str) -> PathBuf {
        static N: AtomicU64 = AtomicU64::new(0);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let dir = std::env::temp_dir().join(format!(
            "trackbelt-plot-{tag}-{}-{nanos}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn line(label: &str, kind: SeriesKind, points: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            points,
            kind,
        }
    }

    fn fig<'a>(title: &'a str, series: &'a [Series], hlines: &'a [HLine]) -> Figure<'a> {
        Figure {
            title,
            x_label: "time [s]",
            y_label: "height [mm]",
            series,
            hlines,
            equal_aspect: false,
        }
    }

    fn assert_svg(path: &Path, needles: &[&str]) -> String {
        let text = fs::read_to_string(path).unwrap();
        assert!(
            text.starts_with("<svg") || text.starts_with("<?xml"),
            "not an SVG: {}",
            &text[..text.len().min(80)]
        );
        assert!(text.trim_end().ends_with("</svg>"), "unterminated SVG");
        for n in needles {
            assert!(text.contains(n), "SVG lacks {n:?}");
        }
        text
    }

    /// Belt-like outline: a stadium shape in mm, x in [-600, 600], y in [0, 800].
    fn belt_outline(scale: f64) -> Vec<(f64, f64)> {
        let (r, half) = (400.0 * scale, 200.0 * scale);
        let mut pts = Vec::new();
        for i in 0..=36 {
            let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * f64::from(i) / 36.0;
            pts.push((half + r * a.cos(), 400.0 + r * a.sin()));
        }
        for i in 0..=36 {
            let a = std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * f64::from(i) / 36.0;
            pts.push((-half + r * a.cos(), 400.0 + r * a.sin()));
        }
        pts.push(pts[0]);
        pts
    }

    #[test]
    fn line_plot_with_hline_and_markers() {
        let dir = temp_dir("line");
        let path = dir.join("sub/dir/settle.svg");
        let series = [
            line(
                "simulated height",
                SeriesKind::Line,
                (0..100)
                    .map(|i| (i as f64 * 0.01, 300.0 + 50.0 * (-(i as f64) * 0.05).exp()))
                    .collect(),
            ),
            line(
                "model prediction",
                SeriesKind::Dashed,
                (0..100)
                    .map(|i| (i as f64 * 0.01, 305.0 + 40.0 * (-(i as f64) * 0.04).exp()))
                    .collect(),
            ),
            line(
                "measured samples",
                SeriesKind::Markers,
                (0..10)
                    .map(|i| (i as f64 * 0.1, 302.0 + 30.0 * (-(i as f64) * 0.5).exp()))
                    .collect(),
            ),
        ];
        let hlines = [HLine {
            label: "measured settled height".into(),
            y: 301.5,
        }];
        write_svg(&path, &fig("Settling <test> & check", &series, &hlines)).unwrap();
        assert_svg(
            &path,
            &[
                "simulated height",
                "model prediction",
                "measured samples",
                "measured settled height",
                "time [s]",
                "height [mm]",
                "Settling &lt;test&gt; &amp; check",
                "<circle",
            ],
        );
        // No temporary files left behind.
        let leftovers: Vec<_> = fs::read_dir(path.parent().unwrap())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name() != "settle.svg")
            .collect();
        assert!(leftovers.is_empty(), "leftover files: {leftovers:?}");

        // Overwriting an existing plot works.
        write_svg(&path, &fig("second", &series, &hlines)).unwrap();
        assert_svg(&path, &["second"]);
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn equal_aspect_shapes() {
        let dir = temp_dir("shape");
        let path = dir.join("shape.svg");
        let series = [
            line("nominal", SeriesKind::Line, belt_outline(1.0)),
            line("loaded", SeriesKind::Dashed, belt_outline(0.95)),
            line(
                "contact",
                SeriesKind::Markers,
                vec![(-200.0, 0.0), (200.0, 0.0)],
            ),
        ];
        let mut f = fig("Belt shape", &series, &[]);
        f.x_label = "x [mm]";
        f.y_label = "y [mm]";
        f.equal_aspect = true;
        write_svg(&path, &f).unwrap();
        assert_svg(&path, &["nominal", "loaded", "contact", "x [mm]"]);

        let (_, layout) = render_figure(&path, &f).unwrap();
        let (w, h) = layout.plot_px;
        assert!(w > 500 && h > 300, "plot area {w}x{h}");
        let sx = (layout.x.1 - layout.x.0) / f64::from(w);
        let sy = (layout.y.1 - layout.y.0) / f64::from(h);
        assert!((sx / sy - 1.0).abs() < 1e-9, "mm/px differ: {sx} vs {sy}");
        // The data still fits.
        assert!(layout.x.0 <= -600.0 && layout.x.1 >= 600.0);
        assert!(layout.y.0 <= 0.0 && layout.y.1 >= 800.0);
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn equalize_widens_the_shorter_range() {
        let ((x0, x1), (y0, y1)) = equalize_ranges((0.0, 10.0), (0.0, 10.0), (200, 100)).unwrap();
        assert_eq!((y0, y1), (0.0, 10.0));
        assert!((x0 + 5.0).abs() < 1e-12 && (x1 - 15.0).abs() < 1e-12);
    }

    #[test]
    fn empty_figure_is_an_error() {
        let dir = temp_dir("empty");
        let path = dir.join("empty.svg");
        let none: [Series; 0] = [];
        let err = write_svg(&path, &fig("nothing", &none, &[])).unwrap_err();
        assert!(matches!(err, PlotError::NoData { .. }), "{err:?}");
        let msg = err.to_string();
        assert!(
            msg.contains("empty.svg") && msg.contains("nothing"),
            "{msg}"
        );

        let all_nan = [line(
            "nan",
            SeriesKind::Line,
            vec![(f64::NAN, 1.0), (2.0, f64::INFINITY)],
        )];
        let hl = [HLine {
            label: "nan".into(),
            y: f64::NAN,
        }];
        let err = write_svg(&path, &fig("nan only", &all_nan, &hl)).unwrap_err();
        assert!(matches!(err, PlotError::NoData { .. }), "{err:?}");
        assert!(!path.exists());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn nan_points_are_ignored() {
        let dir = temp_dir("nan");
        let path = dir.join("nan.svg");
        let series = [
            line(
                "with gaps",
                SeriesKind::Line,
                vec![
                    (0.0, 1.0),
                    (1.0, f64::NAN),
                    (2.0, 3.0),
                    (f64::INFINITY, 4.0),
                    (3.0, 2.0),
                    (4.0, 5.0),
                ],
            ),
            line(
                "dots",
                SeriesKind::Markers,
                vec![(f64::NAN, f64::NAN), (1.5, 2.0)],
            ),
            line(
                "all bad",
                SeriesKind::Dashed,
                vec![(f64::NEG_INFINITY, 0.0)],
            ),
        ];
        let hlines = [
            HLine {
                label: "bad ref".into(),
                y: f64::NAN,
            },
            HLine {
                label: "good ref".into(),
                y: 2.5,
            },
        ];
        let f = fig("gaps", &series, &hlines);
        write_svg(&path, &f).unwrap();
        let text = assert_svg(&path, &["with gaps", "dots", "good ref"]);
        assert!(
            !text.contains("NaN") && !text.contains("inf"),
            "non-finite leaked into SVG"
        );
        let (_, layout) = render_figure(&path, &f).unwrap();
        assert!(layout.x.0 > -1.0 && layout.x.1 < 5.0, "{layout:?}");
        assert!(layout.y.0 > 0.0 && layout.y.1 < 6.0, "{layout:?}");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn grid_with_three_panels() {
        let dir = temp_dir("grid");
        let path = dir.join("variants.svg");
        let a = [line("variant A", SeriesKind::Line, belt_outline(1.0))];
        let b = [line("variant B", SeriesKind::Line, belt_outline(0.9))];
        let c = [line("variant C", SeriesKind::Dashed, belt_outline(0.8))];
        let hl = [HLine {
            label: "ground".into(),
            y: 0.0,
        }];
        let mk = |title, s| Figure {
            title,
            x_label: "x [mm]",
            y_label: "y [mm]",
            series: s,
            hlines: &hl,
            equal_aspect: true,
        };
        let panels = [
            mk("panel A", &a[..]),
            mk("panel B", &b[..]),
            mk("panel C", &c[..]),
        ];
        write_svg_grid(&path, "Three variants", &panels, 3).unwrap();
        assert_svg(
            &path,
            &[
                "Three variants",
                "panel A",
                "panel B",
                "panel C",
                "variant A",
                "variant B",
                "variant C",
                "ground",
            ],
        );
        let (svg, layouts) = render_grid(&path, "Three variants", &panels, 3).unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains(&format!("width=\"{}\"", 3 * PANEL_SIZE.0)));
        assert_eq!(layouts.len(), 3);
        for l in layouts {
            let sx = (l.x.1 - l.x.0) / f64::from(l.plot_px.0);
            let sy = (l.y.1 - l.y.0) / f64::from(l.plot_px.1);
            assert!((sx / sy - 1.0).abs() < 1e-9);
        }

        // Two columns -> two rows; more columns than panels is fine.
        write_svg_grid(&path, "", &panels, 2).unwrap();
        write_svg_grid(&path, "wide", &panels, 100).unwrap();
        assert!(matches!(
            write_svg_grid(&path, "t", &panels, 0),
            Err(PlotError::InvalidInput { .. })
        ));
        assert!(matches!(
            write_svg_grid(&path, "t", &[], 3),
            Err(PlotError::InvalidInput { .. })
        ));
        let empty: [Series; 0] = [];
        let bad = [
            mk("ok", &a[..]),
            Figure {
                hlines: &[],
                ..mk("empty panel", &empty[..])
            },
        ];
        let err = write_svg_grid(&path, "t", &bad, 2).unwrap_err();
        assert!(err.to_string().contains("empty panel"), "{err}");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn extreme_values_do_not_panic() {
        let dir = temp_dir("extreme");
        let path = dir.join("x.svg");
        let cases: Vec<Vec<(f64, f64)>> = vec![
            vec![(1.0, 1.0)],
            vec![(0.0, 0.0), (0.0, 0.0)],
            vec![(1e300, -1e300), (-1e300, 1e300)],
            vec![(f64::MAX, f64::MAX), (-f64::MAX, -f64::MAX)],
            vec![(1e-320, 5e-324), (0.0, 0.0)],
            vec![(1e12, 1e12), (1e12 + 1e-3, 1e12)],
            vec![(-1e-9, 3.0), (1e-9, 3.0 + 1e-12)],
        ];
        for (i, pts) in cases.into_iter().enumerate() {
            for equal_aspect in [false, true] {
                let s = [line("s", SeriesKind::Line, pts.clone())];
                let f = Figure {
                    equal_aspect,
                    ..fig("extreme", &s, &[])
                };
                match write_svg(&path, &f) {
                    Ok(()) => {}
                    Err(PlotError::InvalidInput { .. }) => {}
                    Err(e) => panic!("case {i}: unexpected error {e}"),
                }
            }
        }
        // Only an hline: x falls back to a unit range.
        let hl = [HLine {
            label: "only".into(),
            y: 3.0,
        }];
        write_svg(&path, &fig("hline only", &[], &hl)).unwrap();
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_path_is_an_error() {
        let dir = temp_dir("badpath");
        // A regular file where the parent directory should be.
        let blocker = dir.join("blocker");
        fs::write(&blocker, b"x").unwrap();
        let s = [line("s", SeriesKind::Line, vec![(0.0, 0.0), (1.0, 1.0)])];
        let target = blocker.join("plot.svg");
        let err = write_svg(&target, &fig("t", &s, &[])).unwrap_err();
        assert!(matches!(err, PlotError::Io { .. }), "{err:?}");
        assert!(err.to_string().contains("plot.svg"));
        assert!(std::error::Error::source(&err).is_some());
        // A directory as target: rename fails, temporary file is cleaned up.
        let as_dir = dir.join("isdir.svg");
        fs::create_dir_all(as_dir.join("inner")).unwrap();
        assert!(write_svg(&as_dir, &fig("t", &s, &[])).is_err());
        let names: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
        fs::remove_dir_all(&dir).unwrap();
    }
}

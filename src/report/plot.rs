//! SVG line and bar plots (plotters, SVG backend). The DejaVu Sans font ships in `assets/fonts`
//! and is registered before any text is drawn, so plots render the same on a machine with no
//! fonts.
//!
//! Conventions every figure rotorsim draws follows:
//! - one fixed colour per damper model ([`MODEL_COLOURS`]: measured, linear, nonlinear,
//!   physical), found from the series name, so a model has the same colour in the run report,
//!   the bench and the diagnosis plots; other series take [`OTHER_COLOURS`] in turn;
//! - ticks at "nice" steps (1, 2, 2.5, 5 x 10^k) or at a fixed step ([`Plot::x_step`], e.g. 90 deg
//!   of azimuth), labelled with as many decimals as the step needs, never repeated;
//! - data in SI, shown in engineering units through [`Plot::x_scale`] / [`Plot::y_scale`]
//!   (e.g. N shown in kN with a scale of 1e-3 and an axis label "force [kN]");
//! - the legend to the right of the data area, never over the data.
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

fn register_font() {
    REGISTER.call_once(|| {
        // The font is a compile-time constant known to be valid TrueType.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// The damper models' colours, the same in every plot: the measurement black, the linear
/// dashpot blue, the nonlinear dashpot orange, the physical damper green.
pub const MODEL_COLOURS: [(&str, RGBColor); 4] = [
    ("measured", RGBColor(0, 0, 0)),
    ("linear", RGBColor(31, 119, 180)),
    ("nonlinear", RGBColor(255, 127, 14)),
    ("physical", RGBColor(44, 160, 44)),
];

/// Colours of series that are not a damper model (limits, channels, amplitudes), in turn.
pub const OTHER_COLOURS: [RGBColor; 8] = [
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(0, 0, 128),
];

/// The fixed colour of the damper model a series name refers to: the first word of the name
/// that is a model name ("physical (sdof)", "SYNTHETIC measured (avg of 5 revs)",
/// "linear p0"), or None.
pub fn model_colour(name: &str) -> Option<RGBColor> {
    name.split(|c: char| !c.is_ascii_alphanumeric())
        .find_map(|w| {
            let w = w.to_ascii_lowercase();
            MODEL_COLOURS.iter().find(|m| m.0 == w).map(|m| m.1)
        })
}

/// The stability modes' colours, one per mode family in every report: lag modes in blues and
/// greens, flap modes in oranges, the airframe's directions in reds, purples and greys.
pub const MODE_COLOURS: [(&str, RGBColor); 12] = [
    ("regressing lag", RGBColor(31, 119, 180)),
    ("progressive lag", RGBColor(23, 190, 207)),
    ("collective lag", RGBColor(44, 160, 44)),
    ("differential lag", RGBColor(188, 189, 34)),
    ("regressing flap", RGBColor(255, 127, 14)),
    ("progressive flap", RGBColor(227, 119, 194)),
    ("collective flap", RGBColor(140, 86, 75)),
    ("differential flap", RGBColor(255, 187, 120)),
    ("airframe x", RGBColor(214, 39, 40)),
    ("airframe y", RGBColor(148, 103, 189)),
    ("airframe roll", RGBColor(127, 127, 127)),
    ("airframe pitch", RGBColor(0, 0, 128)),
];

/// The fixed colour of a stability mode label, or None: the family's colour whatever follows
/// it in brackets ("airframe y (real root 2)" is drawn as "airframe y").
pub fn mode_colour(label: &str) -> Option<RGBColor> {
    let family = label.split(" (").next().unwrap_or(label).trim_end();
    MODE_COLOURS.iter().find(|m| m.0 == family).map(|m| m.1)
}

/// The colour as a CSS hex string (for HTML next to the plots).
pub fn css(c: RGBColor) -> String {
    format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesKind {
    /// Solid line.
    Line,
    /// Dashed line (e.g. a reference or a model variant).
    Dashed,
    /// Dotted line (a third channel of the same model).
    Dotted,
    /// Markers only (e.g. measured or digitized data).
    Points,
    /// Bars centred on each x, side by side with the plot's other bar series (harmonics).
    Bars,
    /// Large filled dots (a dot plot's values).
    Dots,
    /// Open rings around points (highlights a dot, e.g. the chosen cause).
    Rings,
    /// A shaded rectangle over the bounding box of the series' points (a band, e.g. noise).
    Band,
    /// Horizontal bars from x = 0 to each x on a categorical y axis, side by side (top to
    /// bottom) with the plot's other horizontal bar series in each row (a tornado chart).
    HBars,
}

/// One named data series.
#[derive(Debug, Clone)]
pub struct Series {
    pub name: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub kind: SeriesKind,
    /// Colour overriding the plot's convention (e.g. grey for the also-rans of a dot plot).
    pub colour: Option<RGBColor>,
}

/// A 2-D plot with any number of series.
#[derive(Debug, Clone)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Axis ranges in data units (SI), before scaling.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    /// Fixed x tick step in displayed units (e.g. 90 for azimuth in deg).
    pub x_step: Option<f64>,
    /// Displayed value = data value * scale (e.g. 1e-3 for N shown in kN).
    pub x_scale: f64,
    pub y_scale: f64,
    /// A categorical y axis: category i is the i-th row from the top, at y = i in the series'
    /// data (a dot plot's rows); `y_scale` and `y_range` do not apply.
    pub y_categories: Option<Vec<String>>,
    /// Draw the legend column (off when the rows already name the series).
    pub legend: bool,
}

/// Errors while drawing.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("plot '{0}' has no finite data")]
    NoData(String),
    #[error("plot '{title}': {message}")]
    Draw { title: String, message: String },
    #[error(transparent)]
    Output(#[from] crate::io::OutputError),
}

/// A closed interval (lo, hi).
type Range = (f64, f64);

/// A linear f64 axis with the ticks given (plotters' own picks its ticks itself).
struct Ticked {
    inner: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;
    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }
    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

fn ticked(lo: f64, hi: f64, ticks: Vec<f64>) -> Ticked {
    Ticked {
        inner: (lo..hi).into(),
        ticks,
    }
}

/// Ticks at a nice step (1, 2, 2.5, 5 x 10^k) with about `target` of them in [lo, hi], and the
/// step.
pub fn nice_ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, f64) {
    let span = hi - lo;
    if span.is_nan() || span <= 0.0 || !span.is_finite() {
        return (vec![lo], 1.0);
    }
    let raw = span / target.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    (ticks_at(lo, hi, step), step)
}

/// Multiples of `step` in [lo, hi] (exact multiples, so 90 deg steps give 0, 90, 180, ...).
pub fn ticks_at(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let k0 = (lo / step - 1e-9).ceil() as i64;
    let k1 = (hi / step + 1e-9).floor() as i64;
    (k0..=k1.min(k0 + 1000)).map(|k| k as f64 * step).collect()
}

/// Decimals that label every multiple of `step` distinctly (0 for 90, 1 for 0.5, 2 for 0.25).
pub fn decimals_for(step: f64) -> usize {
    (0..8)
        .find(|d| {
            let s = step * 10f64.powi(*d as i32);
            (s - s.round()).abs() < 1e-6 * s.abs().max(1.0)
        })
        .unwrap_or(8)
}

/// A tick label: `decimals` after the point, "-0" shown as "0"; beyond 1e5 in magnitude as a
/// power of ten ("2.5e6") so no axis carries a label like "10000000.0".
pub fn tick_label(v: f64, decimals: usize) -> String {
    let v = if v.abs() < 1e-12 { 0.0 } else { v };
    if v.abs() >= 1e5 {
        let s = format!("{v:.3e}");
        // 2.500e6 -> 2.5e6
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    format!("{v:.decimals$}")
}

impl Plot {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            x_range: None,
            y_range: None,
            x_step: None,
            x_scale: 1.0,
            y_scale: 1.0,
            y_categories: None,
            legend: true,
        }
    }

    fn push(mut self, name: &str, x: &[f64], y: &[f64], kind: SeriesKind) -> Self {
        let n = x.len().min(y.len());
        self.series.push(Series {
            name: name.into(),
            x: x[..n].to_vec(),
            y: y[..n].to_vec(),
            kind,
            colour: None,
        });
        self
    }

    pub fn line(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Line)
    }

    pub fn dashed(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Dashed)
    }

    pub fn dotted(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Dotted)
    }

    pub fn points(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Points)
    }

    pub fn bars(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Bars)
    }

    /// Horizontal bars from x = 0 (rows of a categorical y axis: a tornado chart).
    pub fn hbars(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::HBars)
    }

    pub fn dots(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Dots)
    }

    pub fn rings(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Rings)
    }

    /// A shaded band over the bounding box of the points given.
    pub fn band(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Band)
    }

    /// Colour of the last series added (overrides the model colours).
    pub fn colour(mut self, c: RGBColor) -> Self {
        if let Some(s) = self.series.last_mut() {
            s.colour = Some(c);
        }
        self
    }

    /// A categorical y axis, rows named from the top (series' y = row index).
    pub fn y_categories(mut self, names: &[String]) -> Self {
        self.y_categories = Some(names.to_vec());
        self
    }

    /// No legend column.
    pub fn no_legend(mut self) -> Self {
        self.legend = false;
        self
    }

    /// A series of the given kind.
    pub fn series(self, kind: SeriesKind, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, kind)
    }

    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// x ticks every `step` displayed units.
    pub fn x_step(mut self, step: f64) -> Self {
        self.x_step = Some(step);
        self
    }

    /// An azimuth axis: 0..360 deg, ticks every 90 deg.
    pub fn azimuth(self) -> Self {
        self.x_range(0.0, 360.0).x_step(90.0)
    }

    pub fn x_scale(mut self, s: f64) -> Self {
        self.x_scale = s;
        self
    }

    pub fn y_scale(mut self, s: f64) -> Self {
        self.y_scale = s;
        self
    }

    /// Colour of every series: the model's fixed colour, else the other colours in turn; a
    /// series with no name continues the one before it (same colour, no legend entry), e.g. the
    /// markers on a model's line.
    fn colours(&self) -> Vec<RGBColor> {
        let mut k = 0;
        let mut out: Vec<RGBColor> = Vec::with_capacity(self.series.len());
        for s in &self.series {
            let c = match (s.colour, s.name.is_empty(), out.last()) {
                (Some(c), _, _) => c,
                (None, true, Some(&prev)) => prev,
                // per-rev reference lines of a fan plot: background grey
                _ if s.name.ends_with("/rev") => RGBColor(170, 170, 170),
                _ => model_colour(&s.name).unwrap_or_else(|| {
                    let c = OTHER_COLOURS[k % OTHER_COLOURS.len()];
                    k += 1;
                    c
                }),
            };
            out.push(c);
        }
        out
    }

    /// Displayed ranges (scaled).
    fn ranges(&self) -> Result<(Range, Range), PlotError> {
        let (sx, sy) = (self.x_scale, self.y_scale);
        let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
        let mut yr = xr;
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if x.is_finite() && y.is_finite() {
                    xr = (xr.0.min(x * sx), xr.1.max(x * sx));
                    yr = (yr.0.min(y * sy), yr.1.max(y * sy));
                }
            }
        }
        if self.series.iter().any(|s| s.kind == SeriesKind::Bars) && xr.0.is_finite() {
            yr = (yr.0.min(0.0), yr.1.max(0.0));
            xr = (xr.0 - 0.5 * sx.abs(), xr.1 + 0.5 * sx.abs());
        }
        let hbars = self.series.iter().any(|s| s.kind == SeriesKind::HBars);
        if hbars && xr.0.is_finite() {
            // bars start at 0, and none of them should touch the frame
            xr = (xr.0.min(0.0), xr.1.max(0.0));
            let span = xr.1 - xr.0;
            let span = if span > 0.0 { span } else { 1.0 };
            xr = (xr.0 - 0.05 * span, xr.1 + 0.05 * span);
        }
        if !xr.0.is_finite() {
            return Err(PlotError::NoData(self.title.clone()));
        }
        let pad = |r: (f64, f64), frac: f64| {
            let span = r.1 - r.0;
            let span = if span > 0.0 { span } else { r.0.abs().max(1.0) };
            (r.0 - frac * span, r.1 + frac * span)
        };
        let sc = |r: (f64, f64), s: f64| {
            let (a, b) = (r.0 * s, r.1 * s);
            (a.min(b), a.max(b))
        };
        // Lines run edge to edge; markers only (a sweep's cases) would sit on the frame.
        let points_only = self.series.iter().all(|s| {
            matches!(
                s.kind,
                SeriesKind::Points | SeriesKind::Dots | SeriesKind::Rings | SeriesKind::Band
            )
        });
        let xr = self.x_range.map(|r| sc(r, sx)).unwrap_or(if xr.1 <= xr.0 {
            pad(xr, 0.5)
        } else if points_only {
            pad(xr, 0.05)
        } else {
            xr
        });
        let yr = match &self.y_categories {
            Some(c) => (-0.6, c.len() as f64 - 0.4),
            None => self.y_range.map(|r| sc(r, sy)).unwrap_or(pad(yr, 0.05)),
        };
        Ok((xr, yr))
    }

    /// Width of the legend column [px] (0 without named series).
    fn legend_width(&self, width: u32) -> u32 {
        if !self.legend {
            return 0;
        }
        let longest = self
            .series
            .iter()
            .map(|s| s.name.chars().count())
            .max()
            .unwrap_or(0);
        if longest == 0 {
            return 0;
        }
        ((longest as u32) * 8 + 44).min((width * 7 / 20).max(190).min(width / 2))
    }

    /// Width of the y tick labels' area [px]: row names need room (13 px DejaVu Sans: about
    /// 7.5 px a character).
    fn y_label_width(&self, w: u32) -> u32 {
        match &self.y_categories {
            Some(c) => {
                let longest = c.iter().map(|n| n.chars().count()).max().unwrap_or(0);
                ((longest as f64 * 7.5) as u32 + 16).clamp(70, w / 2)
            }
            None => 70,
        }
    }

    fn count_of(&self, kind: SeriesKind) -> usize {
        self.series.iter().filter(|s| s.kind == kind).count()
    }

    /// Tick positions and label decimals of the x and y axes (category rows: one tick a row,
    /// row i from the top at y = ncat - 1 - i).
    #[allow(clippy::type_complexity)]
    fn ticks(
        &self,
        (x0, x1): (f64, f64),
        (y0, y1): (f64, f64),
    ) -> ((Vec<f64>, usize), (Vec<f64>, usize)) {
        let x = match self.x_step {
            Some(s) => (ticks_at(x0, x1, s), decimals_for(s)),
            None => {
                let (t, s) = nice_ticks(x0, x1, 8);
                (t, decimals_for(s))
            }
        };
        let y = match &self.y_categories {
            Some(c) => ((0..c.len()).map(|k| k as f64).collect(), 0),
            None => {
                let (t, s) = nice_ticks(y0, y1, 6);
                (t, decimals_for(s))
            }
        };
        (x, y)
    }

    /// A series' points as drawn: the finite ones, scaled (`fy`: the y axis' map); a marker
    /// outside a y range that was asked for is left out, not drawn over the axes (lines and
    /// bands keep their points).
    fn drawn_points(&self, s: &Series, fy: &dyn Fn(f64) -> f64) -> Vec<(f64, f64)> {
        s.x.iter()
            .zip(&s.y)
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .filter(|(_, &y)| {
                !matches!(
                    s.kind,
                    SeriesKind::Points | SeriesKind::Dots | SeriesKind::Rings
                ) || self.y_categories.is_some()
                    || self.y_range.is_none_or(|(lo, hi)| (lo..=hi).contains(&y))
            })
            .map(|(&x, &y)| (x * self.x_scale, fy(y)))
            .collect()
    }

    fn draw_on<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), PlotError> {
        let err = |e: &dyn std::fmt::Display| PlotError::Draw {
            title: self.title.clone(),
            message: e.to_string(),
        };
        let ((x0, x1), (y0, y1)) = self.ranges()?;
        let (w, _) = area.dim_in_pixel();
        let lw = self.legend_width(w);
        let (plot_area, legend_area) = area.split_horizontally(w - lw);
        let ((xt, dx), (yt, dy)) = self.ticks((x0, x1), (y0, y1));
        let cats = self.y_categories.clone();
        let ncat = cats.as_ref().map_or(0, Vec::len);
        let xfmt = move |v: &f64| tick_label(*v, dx);
        let yfmt = move |v: &f64| match &cats {
            Some(c) => {
                let k = v.round();
                if k >= 0.0 && (k as usize) < c.len() {
                    c[c.len() - 1 - k as usize].clone()
                } else {
                    String::new()
                }
            }
            None => tick_label(*v, dy),
        };
        let y_area = self.y_label_width(w);
        let mut chart = ChartBuilder::on(&plot_area)
            .caption(&self.title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(y_area)
            .build_cartesian_2d(ticked(x0, x1, xt), ticked(y0, y1, yt))
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style(("sans-serif", 13))
            .x_label_formatter(&xfmt)
            .y_label_formatter(&yfmt)
            .bold_line_style(RGBColor(225, 225, 225))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| err(&e))?;
        let colours = self.colours();
        let nbars = self.count_of(SeriesKind::Bars).max(1);
        let nhbars = self.count_of(SeriesKind::HBars).max(1);
        let (mut jbar, mut jhbar) = (0usize, 0usize);
        let (sx, sy) = (self.x_scale, self.y_scale);
        let fy = |y: f64| {
            if ncat > 0 {
                (ncat - 1) as f64 - y
            } else {
                y * sy
            }
        };
        for (s, &color) in self.series.iter().zip(&colours) {
            let pts = self.drawn_points(s, &fy);
            match s.kind {
                SeriesKind::Line => {
                    chart
                        .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                        .map_err(|e| err(&e))?;
                }
                SeriesKind::Dashed => {
                    chart
                        .draw_series(DashedLineSeries::new(pts, 6, 4, color.stroke_width(2)))
                        .map_err(|e| err(&e))?;
                }
                SeriesKind::Dotted => {
                    chart
                        .draw_series(DashedLineSeries::new(pts, 2, 3, color.stroke_width(2)))
                        .map_err(|e| err(&e))?;
                }
                SeriesKind::Points => {
                    chart
                        .draw_series(pts.into_iter().map(|p| Circle::new(p, 2, color.filled())))
                        .map_err(|e| err(&e))?;
                }
                SeriesKind::Dots => {
                    chart
                        .draw_series(pts.into_iter().map(|p| Circle::new(p, 5, color.filled())))
                        .map_err(|e| err(&e))?;
                }
                SeriesKind::Rings => {
                    chart
                        .draw_series(
                            pts.into_iter()
                                .map(|p| Circle::new(p, 9, color.stroke_width(2))),
                        )
                        .map_err(|e| err(&e))?;
                }
                SeriesKind::Band => {
                    let bb = pts.iter().fold(
                        (
                            f64::INFINITY,
                            f64::INFINITY,
                            f64::NEG_INFINITY,
                            f64::NEG_INFINITY,
                        ),
                        |b, &(x, y)| (b.0.min(x), b.1.min(y), b.2.max(x), b.3.max(y)),
                    );
                    if bb.0 <= bb.2 {
                        chart
                            .draw_series(std::iter::once(Rectangle::new(
                                [(bb.0, bb.1), (bb.2, bb.3)],
                                color.mix(0.12).filled(),
                            )))
                            .map_err(|e| err(&e))?;
                    }
                }
                SeriesKind::Bars => {
                    let bw = 0.8 * sx.abs() / nbars as f64;
                    let off = -0.4 * sx.abs() + jbar as f64 * bw;
                    jbar += 1;
                    chart
                        .draw_series(pts.into_iter().map(|(x, y)| {
                            Rectangle::new([(x + off, 0.0), (x + off + bw, y)], color.filled())
                        }))
                        .map_err(|e| err(&e))?;
                }
                SeriesKind::HBars => {
                    // row height 1 in data units: 0.8 of it shared by the series, first on top
                    let bh = 0.8 / nhbars as f64;
                    let top = 0.4 - jhbar as f64 * bh;
                    jhbar += 1;
                    chart
                        .draw_series(pts.into_iter().map(|(x, y)| {
                            Rectangle::new([(0.0, y + top), (x, y + top - bh)], color.filled())
                        }))
                        .map_err(|e| err(&e))?;
                }
            }
        }
        if lw > 0 {
            self.draw_legend(&legend_area, lw, &colours)?;
        }
        Ok(())
    }

    /// The legend column: each named series' marker and its name, cut to fit `lw` px.
    fn draw_legend<DB: DrawingBackend>(
        &self,
        legend_area: &DrawingArea<DB, plotters::coord::Shift>,
        lw: u32,
        colours: &[RGBColor],
    ) -> Result<(), PlotError> {
        let err = |e: &dyn std::fmt::Display| PlotError::Draw {
            title: self.title.clone(),
            message: e.to_string(),
        };
        let max_chars = ((lw.saturating_sub(44)) / 8).max(4) as usize;
        let mut y = 40i32;
        for (s, &color) in self.series.iter().zip(colours) {
            if s.name.is_empty() {
                continue;
            }
            let (x0, x1) = (6i32, 30i32);
            let st = color.stroke_width(2);
            let r = match s.kind {
                SeriesKind::Line => legend_area.draw(&PathElement::new(vec![(x0, y), (x1, y)], st)),
                SeriesKind::Dashed | SeriesKind::Dotted => {
                    let (on, off) = if s.kind == SeriesKind::Dashed {
                        (6, 4)
                    } else {
                        (2, 3)
                    };
                    let mut xa = x0;
                    let mut r = Ok(());
                    while xa < x1 && r.is_ok() {
                        r = legend_area
                            .draw(&PathElement::new(vec![(xa, y), ((xa + on).min(x1), y)], st));
                        xa += on + off;
                    }
                    r
                }
                SeriesKind::Points | SeriesKind::Dots => {
                    legend_area.draw(&Circle::new(((x0 + x1) / 2, y), 3, color.filled()))
                }
                SeriesKind::Rings => {
                    legend_area.draw(&Circle::new(((x0 + x1) / 2, y), 5, color.stroke_width(2)))
                }
                SeriesKind::Band => legend_area.draw(&Rectangle::new(
                    [(x0, y - 5), (x1, y + 5)],
                    color.mix(0.12).filled(),
                )),
                SeriesKind::Bars | SeriesKind::HBars => legend_area.draw(&Rectangle::new(
                    [(x0 + 4, y - 5), (x1 - 4, y + 5)],
                    color.filled(),
                )),
            };
            r.map_err(|e| err(&e))?;
            let mut name: String = s.name.chars().take(max_chars).collect();
            if s.name.chars().count() > max_chars {
                name.pop();
                name.push('…');
            }
            legend_area
                .draw(&Text::new(
                    name,
                    (x1 + 6, y - 7),
                    ("sans-serif", 13).into_font().color(&BLACK),
                ))
                .map_err(|e| err(&e))?;
            y += 20;
        }
        Ok(())
    }

    /// Renders to an SVG document.
    pub fn to_svg(&self, width: u32, height: u32) -> Result<String, PlotError> {
        stacked_svg(std::slice::from_ref(self), width, height)
    }

    /// Renders and writes atomically.
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        crate::io::write_atomic(path, self.to_svg(900, 480)?.as_bytes())?;
        Ok(())
    }
}

/// Several plots stacked vertically in one SVG (e.g. the paper's Fig. 10: stroke over rate).
pub fn stacked_svg(plots: &[Plot], width: u32, height_each: u32) -> Result<String, PlotError> {
    grid_svg(plots, 1, width, height_each)
}

/// Plots in a grid of `cols` columns, row by row, in one SVG `width` wide.
pub fn grid_svg(
    plots: &[Plot],
    cols: usize,
    width: u32,
    height_each: u32,
) -> Result<String, PlotError> {
    register_font();
    let cols = cols.max(1);
    let rows = plots.len().max(1).div_ceil(cols);
    let mut buf = String::new();
    {
        let total_h = height_each * rows as u32;
        let root = SVGBackend::with_string(&mut buf, (width, total_h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| PlotError::Draw {
            title: "figure".into(),
            message: e.to_string(),
        })?;
        let areas = root.split_evenly((rows, cols));
        for (p, a) in plots.iter().zip(areas.iter()) {
            p.draw_on(a)?;
        }
        root.present().map_err(|e| PlotError::Draw {
            title: "figure".into(),
            message: e.to_string(),
        })?;
    }
    Ok(buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_svg_with_labels_and_series() {
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = x.iter().map(|v| v.sin()).collect();
        let svg = Plot::new("sine", "time [s]", "force [N]")
            .line("model", &x, &y)
            .points("measured", &x, &y)
            .to_svg(640, 400)
            .unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("time [s]") && svg.contains("measured"));
        assert!(svg.contains("<polyline") || svg.contains("<path"));
    }

    #[test]
    fn ticks_are_nice_distinct_and_exact() {
        assert_eq!(
            ticks_at(0.0, 360.0, 90.0),
            vec![0.0, 90.0, 180.0, 270.0, 360.0]
        );
        let (t, s) = nice_ticks(-3.2, 7.9, 6);
        assert_eq!(s, 2.0);
        assert_eq!(t, vec![-2.0, 0.0, 2.0, 4.0, 6.0]);
        let (t, s) = nice_ticks(0.0, 0.013, 6);
        let labels: Vec<String> = t.iter().map(|v| tick_label(*v, decimals_for(s))).collect();
        let mut d = labels.clone();
        d.dedup();
        assert_eq!(d, labels, "no repeated tick labels: {labels:?}");
        assert_eq!(tick_label(1.0e7, 1), "1e7");
        assert_eq!(tick_label(-0.0, 0), "0");
        assert_eq!(decimals_for(0.25), 2);
    }

    #[test]
    fn a_model_has_one_colour_whatever_the_label() {
        let lin = model_colour("linear").unwrap();
        assert_eq!(model_colour("linear residual"), Some(lin));
        assert_ne!(model_colour("nonlinear"), Some(lin));
        assert_eq!(model_colour("physical (sdof)"), Some(MODEL_COLOURS[3].1));
        assert_eq!(
            model_colour("SYNTHETIC measured (avg of 5 revs)"),
            Some(MODEL_COLOURS[0].1)
        );
        assert_eq!(model_colour("relief-valve limit (max)"), None);
        for (_, c) in MODEL_COLOURS {
            assert!(!OTHER_COLOURS.contains(&c));
        }
        // an unnamed series (markers on a line) keeps the colour of the series before it
        let p = Plot::new("t", "x", "y")
            .line("nonlinear", &[0.0, 1.0], &[0.0, 1.0])
            .points("", &[0.0, 1.0], &[0.0, 1.0]);
        assert_eq!(p.colours()[1], MODEL_COLOURS[2].1);
    }

    #[test]
    fn a_stability_mode_has_its_family_colour_whatever_the_suffix() {
        let y = mode_colour("airframe y").unwrap();
        assert_eq!(mode_colour("airframe y (real root 1)"), Some(y));
        assert_eq!(mode_colour("airframe y (2)"), Some(y));
        assert_ne!(mode_colour("airframe x"), Some(y));
        assert_eq!(mode_colour("unresolved (1)"), None);
    }

    #[test]
    fn categorical_rows_are_named_top_down() {
        let rows = vec!["first row".to_string(), "second row".to_string()];
        let p = Plot::new("dots", "value [N]", "")
            .y_categories(&rows)
            .no_legend()
            .band("noise", &[0.5, 1.5], &[-0.5, 1.5])
            .dots("a", &[1.0], &[0.0])
            .dots("b", &[2.0], &[1.0])
            .colour(RGBColor(1, 2, 3));
        assert_eq!(p.legend_width(600), 0);
        assert_eq!(p.ranges().unwrap().1, (-0.6, 1.6));
        assert_eq!(p.colours()[2], RGBColor(1, 2, 3));
        let svg = p.to_svg(600, 300).unwrap();
        // the y attribute of the <text> element holding `label`
        let y_of = |label: &str| -> f64 {
            let at = svg.find(label).unwrap();
            let start = svg[..at].rfind("<text").unwrap();
            let tag = &svg[start..at];
            let y = tag.split(" y=\"").nth(1).unwrap();
            y[..y.find('"').unwrap()].parse().unwrap()
        };
        assert!(y_of("first row") < y_of("second row"), "rows top-down");
    }

    #[test]
    fn empty_plot_is_an_error() {
        let e = Plot::new("empty", "x", "y").to_svg(100, 100).unwrap_err();
        assert!(e.to_string().contains("empty"));
    }
}

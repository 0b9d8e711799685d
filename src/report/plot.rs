//! SVG line plots (plotters, SVG backend). The DejaVu Sans font ships in `assets/fonts` and is
//! registered before any text is drawn, so plots render the same on a machine with no fonts.
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

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesKind {
    /// Solid line.
    Line,
    /// Dashed line (e.g. a reference or a model variant).
    Dashed,
    /// Markers only (e.g. measured or digitized data).
    Points,
}

/// One named data series.
#[derive(Debug, Clone)]
pub struct Series {
    pub name: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub kind: SeriesKind,
}

/// A 2-D plot with any number of series.
#[derive(Debug, Clone)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
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

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(0, 0, 0),
];

impl Plot {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            x_range: None,
            y_range: None,
        }
    }

    fn push(mut self, name: &str, x: &[f64], y: &[f64], kind: SeriesKind) -> Self {
        let n = x.len().min(y.len());
        self.series.push(Series {
            name: name.into(),
            x: x[..n].to_vec(),
            y: y[..n].to_vec(),
            kind,
        });
        self
    }

    pub fn line(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Line)
    }

    pub fn dashed(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Dashed)
    }

    pub fn points(self, name: &str, x: &[f64], y: &[f64]) -> Self {
        self.push(name, x, y, SeriesKind::Points)
    }

    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    fn ranges(&self) -> Result<(Range, Range), PlotError> {
        let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
        let mut yr = xr;
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if x.is_finite() && y.is_finite() {
                    xr = (xr.0.min(x), xr.1.max(x));
                    yr = (yr.0.min(y), yr.1.max(y));
                }
            }
        }
        if !xr.0.is_finite() {
            return Err(PlotError::NoData(self.title.clone()));
        }
        let pad = |r: (f64, f64), frac: f64| {
            let span = r.1 - r.0;
            let span = if span > 0.0 { span } else { r.0.abs().max(1.0) };
            (r.0 - frac * span, r.1 + frac * span)
        };
        let xr = self
            .x_range
            .unwrap_or(if xr.1 > xr.0 { xr } else { pad(xr, 0.5) });
        let yr = self.y_range.unwrap_or(pad(yr, 0.05));
        Ok((xr, yr))
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
        let mut chart = ChartBuilder::on(area)
            .caption(&self.title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style(("sans-serif", 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| err(&e))?;
        for (i, s) in self.series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let pts: Vec<(f64, f64)> =
                s.x.iter()
                    .zip(&s.y)
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .map(|(&x, &y)| (x, y))
                    .collect();
            let anno = match s.kind {
                SeriesKind::Line => chart
                    .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                    .map_err(|e| err(&e))?,
                SeriesKind::Dashed => chart
                    .draw_series(DashedLineSeries::new(pts, 6, 4, color.stroke_width(2)))
                    .map_err(|e| err(&e))?,
                SeriesKind::Points => chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                    .map_err(|e| err(&e))?,
            };
            anno.label(s.name.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
            });
        }
        if self.series.iter().any(|s| !s.name.is_empty()) {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 13))
                .draw()
                .map_err(|e| err(&e))?;
        }
        Ok(())
    }

    /// Renders to an SVG document.
    pub fn to_svg(&self, width: u32, height: u32) -> Result<String, PlotError> {
        stacked_svg(std::slice::from_ref(self), width, height)
    }

    /// Renders and writes atomically.
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        crate::io::write_atomic(path, self.to_svg(800, 480)?.as_bytes())?;
        Ok(())
    }
}

/// Several plots stacked vertically in one SVG (e.g. the paper's Fig. 10: stroke over rate).
pub fn stacked_svg(plots: &[Plot], width: u32, height_each: u32) -> Result<String, PlotError> {
    register_font();
    let mut buf = String::new();
    {
        let total_h = height_each * plots.len().max(1) as u32;
        let root = SVGBackend::with_string(&mut buf, (width, total_h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| PlotError::Draw {
            title: "figure".into(),
            message: e.to_string(),
        })?;
        let areas = root.split_evenly((plots.len().max(1), 1));
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
    fn empty_plot_is_an_error() {
        let e = Plot::new("empty", "x", "y").to_svg(100, 100).unwrap_err();
        assert!(e.to_string().contains("empty"));
    }
}

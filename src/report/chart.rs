//! An x–y chart as plain data, drawn as SVG or PNG: the plots of the
//! acceptance report.
//!
//! A [`Chart`] is a title, two axis labels and a list of [`Series`], each a
//! set of points drawn one way ([`Mark`]): a line, a dashed line, ▲ or ▼
//! markers (a run moving ↑ or ↓), dots, or a translucent band (x̄ ± 2s).
//! The legend sits in a strip under the plot, so it never hides data. Text is
//! set in the embedded font of [`crate::report::plot`]; every character the
//! report's charts draw is in it (tested there). Negative tick labels use the
//! minus sign (−), as printed tables do.

use plotters::coord::Shift;
use plotters::element::{DashedPathElement, Polygon};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::report::plot::{Draw, PlotError, PlotFormat, draw_error, render};

/// Size of a chart in pixels (SVG user units), legend included.
pub const CHART_SIZE: (u32, u32) = (960, 600);

/// An RGB colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

/// How a series is drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum Mark {
    /// A line through the points, this many pixels wide.
    Line(u32),
    /// A dashed line through the points.
    Dashed(u32),
    /// ▲ at each point: a reading approached moving ↑.
    Up,
    /// ▼ at each point: a reading approached moving ↓.
    Down,
    /// ● at each point.
    Dot,
    /// A translucent band between each point's y (the lower edge) and the
    /// value of `upper` at the same index.
    Band {
        /// Upper edge, one value per point.
        upper: Vec<f64>,
    },
}

/// One set of points.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text; `None` keeps it out of the legend (e.g. the 2nd…5th run).
    pub label: Option<String>,
    /// Colour.
    pub color: Rgb,
    /// How it is drawn.
    pub mark: Mark,
    /// (x, y) in the axis units.
    pub points: Vec<(f64, f64)>,
}

/// A chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Caption above the plot.
    pub title: String,
    /// Horizontal axis label, with its unit.
    pub x_label: String,
    /// Vertical axis label, with its unit.
    pub y_label: String,
    /// What is drawn, first below.
    pub series: Vec<Series>,
    /// A fixed vertical range (to compare two charts on one scale); `None` fits the data.
    pub y_range: Option<(f64, f64)>,
    /// Drawn around a circle instead of on x–y axes: each point is (angle in
    /// °, deviation), drawn at the angle as a radial offset from a reference
    /// circle; `None`: an x–y chart.
    pub polar: Option<Polar>,
}

/// The scale of a polar chart: a deviation `d` is drawn at radius
/// `reference + d` (one unit of deviation is one unit of radius), with rings
/// at `reference ± ring` labelled `±ring` and the reference circle `0`.
#[derive(Clone, Debug, PartialEq)]
pub struct Polar {
    /// Radius of the reference circle (zero deviation), in deviation units.
    pub reference: f64,
    /// The deviation of the inner and outer rings, in deviation units.
    pub ring: f64,
    /// The deviation's unit, after the ring labels (`″`, ` µrad`).
    pub unit: String,
}

impl Polar {
    /// The scale for deviations up to `largest` in size: rings at the next
    /// 1, 2 or 5 × 10ⁿ at or above it, the reference circle at twice that,
    /// so every deviation lies between half and one and a half of its radius.
    pub fn fitting(largest: f64, unit: &str) -> Polar {
        let largest = if largest.is_finite() && largest > 0.0 {
            largest
        } else {
            1.0
        };
        let power = 10f64.powf(largest.log10().floor());
        let ring = [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|step| step * power)
            .find(|ring| *ring >= largest * (1.0 - 1e-12))
            .unwrap_or(10.0 * power);
        Polar {
            reference: 2.0 * ring,
            ring,
            unit: unit.to_string(),
        }
    }

    /// Where a point (angle °, deviation) is drawn: 0° to the right, angles
    /// counter-clockwise.
    pub fn xy(&self, (angle_deg, deviation): (f64, f64)) -> (f64, f64) {
        let radius = self.reference + deviation;
        let angle = angle_deg.to_radians();
        (radius * angle.cos(), radius * angle.sin())
    }
}

impl Chart {
    /// The smallest and largest y of all points (band edges included).
    pub fn y_extent(&self) -> Option<(f64, f64)> {
        extent(self.series.iter().flat_map(series_ys))
    }

    /// The smallest and largest x of all points.
    pub fn x_extent(&self) -> Option<(f64, f64)> {
        extent(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0)),
        )
    }

    /// Every text the chart draws (for the font coverage test).
    pub fn texts(&self) -> Vec<&str> {
        let mut texts = vec![
            self.title.as_str(),
            self.x_label.as_str(),
            self.y_label.as_str(),
        ];
        texts.extend(self.series.iter().filter_map(|s| s.label.as_deref()));
        if let Some(polar) = &self.polar {
            texts.push(polar.unit.as_str());
        }
        texts
    }
}

/// Draws a chart as SVG text or PNG bytes of [`CHART_SIZE`]. A PNG draws
/// its text in the embedded font, which has every character a chart writes,
/// the arc-second sign ″ included (`assets/fonts/LICENSE`).
pub fn chart(chart: &Chart, format: PlotFormat) -> Result<Vec<u8>, PlotError> {
    render(chart, CHART_SIZE, format)
}

/// A tick label: up to three decimals, trailing zeros dropped, and the
/// minus sign (U+2212) for negative values.
pub fn tick_label(value: f64) -> String {
    let text = format!("{value:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    match text {
        "-0" | "" => "0".to_string(),
        _ => text.replacen('-', "\u{2212}", 1),
    }
}

const FONT_FAMILY: &str = "sans-serif";
const LEGEND_FONT_PX: u32 = 15;
const LEGEND_ROW_PX: u32 = 24;
const LEGEND_SYMBOL_PX: i32 = 28;
const MARKER_PX: i32 = 5;
const BAND_ALPHA: f64 = 0.2;

fn series_ys(series: &Series) -> Vec<f64> {
    let mut ys: Vec<f64> = series.points.iter().map(|p| p.1).collect();
    if let Mark::Band { upper } = &series.mark {
        ys.extend(upper);
    }
    ys
}

fn extent(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .filter(|v| v.is_finite())
        .fold(None, |range, v| match range {
            None => Some((v, v)),
            Some((low, high)) => Some((f64::min(low, v), f64::max(high, v))),
        })
}

/// Pads a range by a fraction of its span on each side; a zero span gets ±1.
fn padded((low, high): (f64, f64), fraction: f64) -> (f64, f64) {
    let span = high - low;
    if span <= f64::EPSILON * high.abs().max(1.0) {
        return (low - 1.0, high + 1.0);
    }
    (low - span * fraction, high + span * fraction)
}

fn color(rgb: Rgb) -> RGBColor {
    RGBColor(rgb.0, rgb.1, rgb.2)
}

impl Draw for Chart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(draw_error)?;
        let legend = legend_layout(self, root)?;
        let (_, height) = root.dim_in_pixel();
        let legend_height = legend.rows * LEGEND_ROW_PX + if legend.rows > 0 { 12 } else { 0 };
        let (plot_area, legend_area) = root.split_vertically(height - legend_height);
        self.draw_plot(&plot_area)?;
        draw_legend(&legend_area, &legend)
    }
}

impl Chart {
    fn draw_plot<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        if let Some(polar) = &self.polar {
            return self.draw_polar(area, polar);
        }
        let x_range = padded(self.x_extent().unwrap_or((0.0, 1.0)), 0.02);
        let y_range = match self.y_range {
            Some(range) => range,
            None => padded(self.y_extent().unwrap_or((0.0, 1.0)), 0.06),
        };
        let mut chart = ChartBuilder::on(area)
            .caption(&self.title, (FONT_FAMILY, 20))
            .margin(14)
            .x_label_area_size(46)
            .y_label_area_size(62)
            .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
            .map_err(draw_error)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&|v| tick_label(*v))
            .y_label_formatter(&|v| tick_label(*v))
            .bold_line_style(RGBColor(215, 215, 215))
            .light_line_style(RGBColor(240, 240, 240))
            .label_style((FONT_FAMILY, 14))
            .axis_desc_style((FONT_FAMILY, 16))
            .draw()
            .map_err(draw_error)?;
        for series in &self.series {
            let rgb = color(series.color);
            let points = series.points.iter().copied();
            match &series.mark {
                Mark::Line(width) => chart
                    .draw_series(std::iter::once(PathElement::new(
                        points.collect::<Vec<_>>(),
                        rgb.stroke_width(*width),
                    )))
                    .map(|_| ()),
                Mark::Dashed(width) => chart
                    .draw_series(std::iter::once(DashedPathElement::new(
                        points,
                        9,
                        6,
                        rgb.stroke_width(*width),
                    )))
                    .map(|_| ()),
                Mark::Up => chart
                    .draw_series(points.map(|p| EmptyElement::at(p) + triangle(true, rgb)))
                    .map(|_| ()),
                Mark::Down => chart
                    .draw_series(points.map(|p| EmptyElement::at(p) + triangle(false, rgb)))
                    .map(|_| ()),
                Mark::Dot => chart
                    .draw_series(points.map(|p| Circle::new(p, 3, rgb.filled())))
                    .map(|_| ()),
                Mark::Band { upper } => {
                    let mut outline: Vec<(f64, f64)> = series.points.clone();
                    outline.extend(
                        series
                            .points
                            .iter()
                            .zip(upper)
                            .rev()
                            .map(|(p, high)| (p.0, *high)),
                    );
                    chart
                        .draw_series(std::iter::once(Polygon::new(
                            outline,
                            rgb.mix(BAND_ALPHA).filled(),
                        )))
                        .map(|_| ())
                }
            }
            .map_err(draw_error)?;
        }
        Ok(())
    }
}

impl Chart {
    /// A polar chart: a square of equal scales in the middle of `area`, the
    /// reference circle and its rings, spokes every 30° labelled with their
    /// angle, the ring labels on the 0° spoke; then the series.
    fn draw_polar<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        polar: &Polar,
    ) -> Result<(), PlotError> {
        let area = area
            .titled(&self.title, (FONT_FAMILY, 20))
            .map_err(draw_error)?;
        let (width, height) = area.dim_in_pixel();
        let side = width.min(height).saturating_sub(8);
        let left = (width - side) / 2;
        let square = area.shrink((left, 4), (side, side));
        // Room outside the outer ring for the angle labels.
        let extent = (polar.reference + polar.ring) * 1.22;
        let mut chart = ChartBuilder::on(&square)
            .build_cartesian_2d(-extent..extent, -extent..extent)
            .map_err(draw_error)?;
        let circle = |radius: f64| -> Vec<(f64, f64)> {
            (0..=360)
                .map(|k| {
                    let angle = f64::from(k).to_radians();
                    (radius * angle.cos(), radius * angle.sin())
                })
                .collect()
        };
        let outer = polar.reference + polar.ring;
        for angle in (0..360).step_by(30) {
            let a = f64::from(angle).to_radians();
            let spoke = vec![(0.0, 0.0), (outer * a.cos(), outer * a.sin())];
            chart
                .draw_series(std::iter::once(PathElement::new(
                    spoke,
                    RGBColor(225, 225, 225).stroke_width(1),
                )))
                .map_err(draw_error)?;
            let at = (outer + polar.ring * 0.35) * 1.0;
            let style = TextStyle::from((FONT_FAMILY, 14).into_font())
                .pos(Pos::new(HPos::Center, VPos::Center));
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{angle}°"),
                    (at * a.cos(), at * a.sin()),
                    style,
                )))
                .map_err(draw_error)?;
        }
        for (radius, colour, width) in [
            (polar.reference - polar.ring, RGBColor(200, 200, 200), 1),
            (outer, RGBColor(200, 200, 200), 1),
            (polar.reference, RGBColor(110, 110, 110), 2),
        ] {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    circle(radius),
                    colour.stroke_width(width),
                )))
                .map_err(draw_error)?;
        }
        let label =
            TextStyle::from((FONT_FAMILY, 13).into_font()).pos(Pos::new(HPos::Left, VPos::Bottom));
        for (offset, text) in [
            (
                -polar.ring,
                format!("{}{}", tick_label(-polar.ring), polar.unit),
            ),
            (0.0, format!("0{}", polar.unit)),
            (
                polar.ring,
                format!("+{}{}", tick_label(polar.ring), polar.unit),
            ),
        ] {
            chart
                .draw_series(std::iter::once(Text::new(
                    text,
                    (polar.reference + offset, 0.0),
                    label.clone(),
                )))
                .map_err(draw_error)?;
        }
        for series in &self.series {
            let rgb = color(series.color);
            let points: Vec<(f64, f64)> = series.points.iter().map(|p| polar.xy(*p)).collect();
            match &series.mark {
                Mark::Dashed(width) => chart
                    .draw_series(std::iter::once(DashedPathElement::new(
                        points,
                        9,
                        6,
                        rgb.stroke_width(*width),
                    )))
                    .map(|_| ()),
                Mark::Line(width) => chart
                    .draw_series(std::iter::once(PathElement::new(
                        points,
                        rgb.stroke_width(*width),
                    )))
                    .map(|_| ()),
                _ => chart
                    .draw_series(points.into_iter().map(|p| Circle::new(p, 3, rgb.filled())))
                    .map(|_| ()),
            }
            .map_err(draw_error)?;
        }
        Ok(())
    }
}

/// A ▲ (pointing up) or ▼ marker around the origin, in pixels.
fn triangle(up: bool, rgb: RGBColor) -> Polygon<(i32, i32)> {
    let (tip, base) = if up {
        (-MARKER_PX, MARKER_PX - 1)
    } else {
        (MARKER_PX, -(MARKER_PX - 1))
    };
    Polygon::new(
        vec![(0, tip), (MARKER_PX, base), (-MARKER_PX, base)],
        rgb.filled(),
    )
}

/// Where the legend entries go: (series index, x, row) and the number of rows.
struct LegendLayout<'a> {
    entries: Vec<(&'a Series, i32, u32)>,
    rows: u32,
}

fn legend_layout<'a, DB: DrawingBackend>(
    chart: &'a Chart,
    root: &DrawingArea<DB, Shift>,
) -> Result<LegendLayout<'a>, PlotError> {
    let style = TextStyle::from((FONT_FAMILY, LEGEND_FONT_PX).into_font());
    let (width, _) = root.dim_in_pixel();
    let left = 76;
    let right = width as i32 - 14;
    let mut entries = Vec::new();
    let (mut x, mut row) = (left, 0);
    for series in &chart.series {
        let Some(label) = &series.label else { continue };
        let (text_width, _) = root.estimate_text_size(label, &style).map_err(draw_error)?;
        let entry_width = LEGEND_SYMBOL_PX + 8 + text_width as i32 + 22;
        if x + entry_width > right && x > left {
            x = left;
            row += 1;
        }
        entries.push((series, x, row));
        x += entry_width;
    }
    let rows = if entries.is_empty() { 0 } else { row + 1 };
    Ok(LegendLayout { entries, rows })
}

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    legend: &LegendLayout<'_>,
) -> Result<(), PlotError> {
    let style = TextStyle::from((FONT_FAMILY, LEGEND_FONT_PX).into_font())
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (series, x, row) in &legend.entries {
        let y = (*row * LEGEND_ROW_PX + LEGEND_ROW_PX / 2) as i32;
        let rgb = color(series.color);
        let middle = x + LEGEND_SYMBOL_PX / 2;
        let end = x + LEGEND_SYMBOL_PX;
        match &series.mark {
            Mark::Line(width) => area.draw(&PathElement::new(
                vec![(*x, y), (end, y)],
                rgb.stroke_width((*width).max(2)),
            )),
            Mark::Dashed(width) => area.draw(&DashedPathElement::new(
                vec![(*x, y), (end, y)],
                9,
                6,
                rgb.stroke_width((*width).max(2)),
            )),
            Mark::Up => area.draw(&(EmptyElement::at((middle, y)) + triangle(true, rgb))),
            Mark::Down => area.draw(&(EmptyElement::at((middle, y)) + triangle(false, rgb))),
            Mark::Dot => area.draw(&Circle::new((middle, y), 3, rgb.filled())),
            Mark::Band { .. } => area.draw(&Rectangle::new(
                [(*x, y - 7), (end, y + 7)],
                rgb.mix(BAND_ALPHA * 1.5).filled(),
            )),
        }
        .map_err(draw_error)?;
        let label = series.label.as_deref().unwrap_or_default();
        area.draw_text(label, &style, (end + 8, y))
            .map_err(draw_error)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Chart {
        Chart {
            title: "Positional deviation".into(),
            x_label: "target position [mm]".into(),
            y_label: "deviation [µm]".into(),
            series: vec![
                Series {
                    label: Some("±2s band ↑".into()),
                    color: Rgb(30, 90, 170),
                    mark: Mark::Band {
                        upper: vec![3.0, 4.0, 5.0],
                    },
                    points: vec![(0.0, -1.0), (100.0, 0.0), (200.0, 1.0)],
                },
                Series {
                    label: Some("runs ↑".into()),
                    color: Rgb(30, 90, 170),
                    mark: Mark::Up,
                    points: vec![(0.0, 1.0), (100.0, 2.0), (200.0, 3.0)],
                },
                Series {
                    label: None,
                    color: Rgb(200, 80, 30),
                    mark: Mark::Down,
                    points: vec![(0.0, -2.0), (200.0, -4.0)],
                },
            ],
            y_range: None,
            polar: None,
        }
    }

    #[test]
    fn a_polar_scale_rings_at_a_round_value_above_the_largest_deviation() {
        let polar = Polar::fitting(6.3, "″");
        assert_eq!((polar.ring, polar.reference), (10.0, 20.0));
        assert_eq!(Polar::fitting(1.5, "″").ring, 2.0);
        assert_eq!(Polar::fitting(0.04, "″").ring, 0.05);
        assert_eq!(Polar::fitting(0.0, "″").ring, 1.0);
        // 90° is straight up, at the reference radius plus the deviation.
        let (x, y) = polar.xy((90.0, 5.0));
        assert!(x.abs() < 1e-12 && (y - 25.0).abs() < 1e-12);
    }

    #[test]
    fn a_polar_chart_draws_its_circles_and_angles_in_svg_and_png() {
        let mut polar = sample();
        polar.series.truncate(0);
        polar.series.push(Series {
            label: Some("mean ↑".into()),
            color: Rgb(30, 90, 170),
            mark: Mark::Line(2),
            points: vec![(0.0, 1.0), (90.0, -2.0), (180.0, 3.0)],
        });
        polar.polar = Some(Polar::fitting(3.0, "″"));
        let svg = String::from_utf8(chart(&polar, PlotFormat::Svg).unwrap()).unwrap();
        for text in ["0°", "90°", "330°", "0″", "+5″", "−5″", "mean ↑"] {
            assert!(svg.contains(text), "{text} missing");
        }
        assert!(chart(&polar, PlotFormat::Png).is_ok());
    }

    #[test]
    fn extents_include_band_edges() {
        let chart = sample();
        assert_eq!(chart.y_extent(), Some((-4.0, 5.0)));
        assert_eq!(chart.x_extent(), Some((0.0, 200.0)));
    }

    #[test]
    fn tick_labels_use_the_minus_sign_and_no_trailing_zeros() {
        assert_eq!(tick_label(-2.5), "−2.5");
        assert_eq!(tick_label(100.0), "100");
        assert_eq!(tick_label(-0.0001), "0");
        assert_eq!(tick_label(0.125), "0.125");
    }

    #[test]
    fn svg_has_the_texts_markers_and_legend() {
        let svg = String::from_utf8(chart(&sample(), PlotFormat::Svg).unwrap()).unwrap();
        assert!(svg.starts_with("<svg"));
        for text in [
            "Positional deviation",
            "deviation [µm]",
            "runs ↑",
            "±2s band ↑",
        ] {
            assert!(svg.contains(text), "{text} missing");
        }
        // Three ▲ and two ▼ markers, the band, and one legend ▲: six polygons or more.
        assert!(svg.matches("<polygon").count() >= 6, "{svg}");
        // The unlabelled ▼ series is not in the legend.
        assert!(!svg.contains("runs ↓"));
    }

    #[test]
    fn png_decodes_to_the_chart_size_and_is_not_blank() {
        let bytes = chart(&sample(), PlotFormat::Png).unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut pixels).unwrap();
        assert_eq!((info.width, info.height), CHART_SIZE);
        let coloured = pixels
            .chunks(3)
            .filter(|p| p[0] != p[1] || p[1] != p[2])
            .count();
        assert!(coloured > 500, "{coloured} coloured pixels");
    }
}

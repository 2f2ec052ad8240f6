//! Plots as bytes: the histogram of `axcomp tolerance` as SVG or PNG, and
//! the drawing of every plot (`render`), which `chart` uses too.
//!
//! Drawn with `plotters`. Text is laid out with an embedded subset of DejaVu
//! Sans (`assets/fonts/`, Bitstream Vera licence) through plotters'
//! `ab_glyph` backend, so no system font or fontconfig is needed and the
//! output is the same on every machine. The PNG is encoded in memory; like
//! every renderer here this returns bytes and `crate::output::write_new`
//! writes the file.

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use crate::report::tolerance::HistogramJson;

/// The embedded font (see `assets/fonts/LICENSE`); the HTML report embeds it too.
pub(crate) const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");

/// Plot size in pixels (SVG user units).
const SIZE: (u32, u32) = (900, 540);

/// The formats a plot can be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotFormat {
    /// Scalable vector graphics.
    Svg,
    /// Portable network graphics, 8-bit RGB.
    Png,
}

impl PlotFormat {
    /// The format named by a file's extension (`.svg`, `.png`, any case).
    pub fn from_path(path: &Path) -> Option<PlotFormat> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "svg" => Some(PlotFormat::Svg),
            "png" => Some(PlotFormat::Png),
            _ => None,
        }
    }
}

/// Why a plot could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The embedded font was rejected (a build defect, not a user error).
    #[error("the embedded plot font could not be loaded")]
    Font,
    /// plotters failed.
    #[error("cannot draw the plot: {0}")]
    Draw(String),
    /// The PNG encoder failed.
    #[error("cannot encode the PNG: {0}")]
    Png(String),
}

/// The histogram of the largest volumetric error per machine, with its P90 marked.
pub fn histogram(
    histogram: &HistogramJson,
    p90_um: f64,
    title: &str,
    format: PlotFormat,
) -> Result<Vec<u8>, PlotError> {
    let plot = HistogramPlot {
        histogram,
        p90_um,
        title,
    };
    render(&plot, SIZE, format)
}

/// A plot that can be drawn on any plotters backend (SVG or bitmap).
pub(crate) trait Draw {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// Draws a plot as SVG text or PNG bytes of `size` pixels.
pub(crate) fn render(
    plot: &impl Draw,
    size: (u32, u32),
    format: PlotFormat,
) -> Result<Vec<u8>, PlotError> {
    register_embedded_font()?;
    match format {
        PlotFormat::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                plot.draw(&root)?;
                root.present().map_err(draw_error)?;
            }
            Ok(svg.into_bytes())
        }
        PlotFormat::Png => {
            let (width, height) = size;
            let mut rgb = vec![0u8; (width * height * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
                plot.draw(&root)?;
                root.present().map_err(draw_error)?;
            }
            encode_png(&rgb, size)
        }
    }
}

fn register_embedded_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok =
        *REGISTERED.get_or_init(|| register_font("sans-serif", FontStyle::Normal, FONT).is_ok());
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

pub(crate) fn draw_error(error: impl std::fmt::Display) -> PlotError {
    PlotError::Draw(error.to_string())
}

struct HistogramPlot<'a> {
    histogram: &'a HistogramJson,
    p90_um: f64,
    title: &'a str,
}

impl Draw for HistogramPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw_histogram(root, self.histogram, self.p90_um, self.title)
    }
}

fn draw_histogram<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    histogram: &HistogramJson,
    p90_um: f64,
    title: &str,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(draw_error)?;
    let low = histogram.edges_um.first().copied().unwrap_or(0.0);
    let mut high = histogram.edges_um.last().copied().unwrap_or(1.0);
    if high <= low {
        high = low + 1.0;
    }
    let tallest = histogram.counts.iter().copied().max().unwrap_or(0).max(1);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(low..high, 0u64..tallest + tallest / 10 + 1)
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_desc("largest volumetric error per machine [µm]")
        .x_label_formatter(&|value| format!("{value:.0}"))
        .y_desc("machines")
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()
        .map_err(draw_error)?;
    let bars = histogram.counts.iter().enumerate().map(|(index, count)| {
        let (left, right) = (histogram.edges_um[index], histogram.edges_um[index + 1]);
        Rectangle::new(
            [(left, 0), (right, *count)],
            RGBColor(70, 110, 170).filled(),
        )
    });
    chart.draw_series(bars).map_err(draw_error)?;
    let top = tallest + tallest / 10;
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(p90_um, 0), (p90_um, top)],
            RGBColor(200, 40, 40).stroke_width(2),
        )))
        .map_err(draw_error)?
        .label(format!("P90 = {p90_um:.1} µm"))
        .legend(|(x, y)| {
            PathElement::new(
                vec![(x, y), (x + 20, y)],
                RGBColor(200, 40, 40).stroke_width(2),
            )
        });
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(draw_error)?;
    Ok(())
}

fn encode_png(rgb: &[u8], (width, height): (u32, u32)) -> Result<Vec<u8>, PlotError> {
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder
            .write_header()
            .map_err(|e| PlotError::Png(e.to_string()))?;
        writer
            .write_image_data(rgb)
            .map_err(|e| PlotError::Png(e.to_string()))?;
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> HistogramJson {
        HistogramJson {
            edges_um: vec![20.0, 40.0, 60.0, 80.0, 100.0],
            counts: vec![3, 10, 6, 1],
        }
    }

    #[test]
    fn svg_has_the_bars_and_the_labels() {
        let bytes = histogram(&sample(), 75.0, "test", PlotFormat::Svg).unwrap();
        let svg = String::from_utf8(bytes).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
        assert!(svg.contains("P90 = 75.0 µm"));
        assert!(svg.contains("largest volumetric error per machine [µm]"));
        assert!(svg.matches("<rect").count() >= 4);
    }

    #[test]
    fn png_decodes_to_the_plot_size() {
        let bytes = histogram(&sample(), 75.0, "test", PlotFormat::Png).unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let reader = decoder.read_info().unwrap();
        let info = reader.info();
        assert_eq!((info.width, info.height), SIZE);
    }

    #[test]
    fn formats_from_extensions() {
        assert_eq!(
            PlotFormat::from_path(Path::new("h.SVG")),
            Some(PlotFormat::Svg)
        );
        assert_eq!(
            PlotFormat::from_path(Path::new("dir/h.png")),
            Some(PlotFormat::Png)
        );
        assert_eq!(PlotFormat::from_path(Path::new("h.pdf")), None);
        assert_eq!(PlotFormat::from_path(Path::new("h")), None);
    }
}

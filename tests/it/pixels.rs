//! Reading PNGs (the report's plots, the browser's screenshots) and where
//! test artefacts are kept for a person to look at. Shared by both test
//! targets.

use std::path::{Path, PathBuf};

/// Where screenshots and PDFs are kept for a person to look at.
pub fn artefacts() -> PathBuf {
    let directory = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("report");
    std::fs::create_dir_all(&directory).unwrap();
    directory
}

/// A decoded PNG: width, height, and its pixels as RGB(A) rows.
pub struct Pixels {
    pub size: (u32, u32),
    channels: usize,
    data: Vec<u8>,
}

impl Pixels {
    pub fn read(path: &Path) -> Pixels {
        let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        let mut data = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut data).unwrap();
        data.truncate(info.buffer_size());
        Pixels {
            size: (info.width, info.height),
            channels: info.color_type.samples(),
            data,
        }
    }

    /// The fraction of pixels for which `test(r, g, b)` holds.
    pub fn fraction(&self, test: impl Fn(u8, u8, u8) -> bool) -> f64 {
        let total = self.data.len() / self.channels;
        let hits = self
            .data
            .chunks(self.channels)
            .filter(|p| match p {
                [r, g, b, ..] => test(*r, *g, *b),
                [grey, ..] => test(*grey, *grey, *grey),
                [] => false,
            })
            .count();
        hits as f64 / total as f64
    }

    /// The fraction that is not (nearly) white.
    pub fn inked(&self) -> f64 {
        self.fraction(|r, g, b| r.min(g).min(b) < 235)
    }

    /// The fraction in the plots' blues (↑ runs, bands): a plot is drawn, not only text.
    // Only the browser tests (the `system` target) look for the plots' blue.
    #[allow(dead_code)]
    pub fn blue(&self) -> f64 {
        self.fraction(|r, _, b| i32::from(b) > i32::from(r) + 60)
    }
}

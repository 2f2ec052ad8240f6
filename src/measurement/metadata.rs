//! What a measurement file records besides its numbers: the conditions at
//! the start and the end, the dates, the format, where the axis' name came
//! from, and the test's set-up.

use std::fmt;
use std::path::PathBuf;

use chrono::NaiveDateTime;

use crate::units::LengthUnit;

/// A value recorded at the start and at the end of the test.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StartEnd {
    /// At the start of the test.
    pub start: Option<f64>,
    /// At the end of the test.
    pub end: Option<f64>,
}

impl StartEnd {
    /// Both values, when known.
    pub fn new(start: Option<f64>, end: Option<f64>) -> StartEnd {
        StartEnd { start, end }
    }

    /// Whether neither value is known.
    pub fn is_empty(&self) -> bool {
        self.start.is_none() && self.end.is_none()
    }
}

/// The test conditions, in SI-style units whatever the source file used.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Environment {
    /// Air temperature, °C.
    pub air_temperature_c: StartEnd,
    /// Air pressure, kPa.
    pub air_pressure_kpa: StartEnd,
    /// Relative humidity, %.
    pub air_humidity_pct: StartEnd,
    /// Up to three material temperature sensors, °C; `None` where no sensor was fitted.
    pub material_temperature_c: [StartEnd; 3],
    /// Expansion coefficient used for the normal-temperature correction, µm/(m·K) (ppm/°C).
    pub expansion_coefficient_ppm_per_k: Option<f64>,
    /// Renishaw's "environmental factor": the half wavelength in air the laser
    /// used, λ_vac / (2·n_air), in µm (`../shared/spec/renishaw-rtl.md`).
    pub environmental_factor_um: StartEnd,
    /// The laser's vacuum wavelength, µm, when the file records it.
    pub vacuum_wavelength_um: Option<f64>,
}

/// The date of the test as the file wrote it, and parsed when the pattern is known.
#[derive(Clone, Debug, PartialEq)]
pub struct TestDate {
    /// The text in the file.
    pub raw: String,
    /// The parsed date and time, when `raw` matched a known pattern.
    pub parsed: Option<NaiveDateTime>,
}

/// The input formats axcomp reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SourceFormat {
    /// Renishaw LaserXL / Laser10 `.rtl` linear data.
    Rtl,
    /// ESS/PSI ecmc ISO 230-2 data file (`TGT_DATA[i]=`, `REF_DATA_FWD[i,j]=`).
    Ecmc,
    /// API XD laser `.pos` linear data table.
    ApiPos,
    /// axcomp's plain CSV (`target_mm,run,direction,deviation_um`).
    Csv,
}

impl SourceFormat {
    /// Every format, in the order they are listed to users.
    pub const ALL: [SourceFormat; 4] = [
        SourceFormat::Rtl,
        SourceFormat::Ecmc,
        SourceFormat::ApiPos,
        SourceFormat::Csv,
    ];

    /// The name used by `--format` and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            SourceFormat::Rtl => "rtl",
            SourceFormat::Ecmc => "ecmc",
            SourceFormat::ApiPos => "api-pos",
            SourceFormat::Csv => "csv",
        }
    }

    /// What it is, for lists of supported formats.
    pub fn description(self) -> &'static str {
        match self {
            SourceFormat::Rtl => "Renishaw .rtl linear data (first line HEADER::)",
            SourceFormat::Ecmc => "ESS/PSI ISO 230-2 data file (TGT_DATA[i]=, REF_DATA_FWD[i,j]=)",
            SourceFormat::ApiPos => "API XD laser .pos linear data table (LinearError column)",
            SourceFormat::Csv => "axcomp CSV (header target_mm,run,direction,deviation_um)",
        }
    }

    /// Looks a format up by its `--format` name.
    pub fn from_name(name: &str) -> Option<SourceFormat> {
        SourceFormat::ALL
            .into_iter()
            .find(|format| format.name().eq_ignore_ascii_case(name))
    }
}

/// Where a measurement's axis name came from.
///
/// A table written for the wrong axis compensates a correct axis with another
/// axis' error, so the name is never guessed silently: a reader records which
/// field of the file states it, and a file that states none is
/// [`AxisSource::NotRecorded`], its name the placeholder
/// [`AXIS_PLACEHOLDER`]. The CLI shows "not recorded" and refuses to write
/// or read a table for such a measurement until the user names the axis.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum AxisSource {
    /// The measurement file states the axis, in this field: `Axis` (`.rtl`
    /// USER-TEXT), `TestAxis` or `File Name` (API `.pos`), `# axis` (CSV),
    /// `TGT_SET_PV`, `REF_PV` or `file name` (ecmc, see [`crate::read::ecmc`]).
    File {
        /// The field, as the file spells it.
        field: String,
    },
    /// Named outside the file: by the user (`--axis`), or by the program that
    /// made the measurement (synth from its truth file, servo-sim, predict).
    Given,
    /// Nothing states the axis; the name is the placeholder [`AXIS_PLACEHOLDER`].
    #[default]
    NotRecorded,
}

/// The name a measurement whose file states no axis carries
/// ([`AxisSource::NotRecorded`]): the first axis, so that figures can be
/// computed, but never used for a table without the user's word.
pub const AXIS_PLACEHOLDER: &str = "X";

impl AxisSource {
    /// The source of a name found in `field` of the file.
    pub fn file(field: impl Into<String>) -> AxisSource {
        AxisSource::File {
            field: field.into(),
        }
    }

    /// Whether the file or the user named the axis.
    pub fn is_recorded(&self) -> bool {
        !matches!(self, AxisSource::NotRecorded)
    }
}

impl fmt::Display for AxisSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AxisSource::File { field } => write!(f, "from {field} in the file"),
            AxisSource::Given => f.write_str("given, not from the file"),
            AxisSource::NotRecorded => f.write_str("not recorded"),
        }
    }
}

/// Who measured what, where and when; all optional, as files leave fields empty.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metadata {
    /// Machine name or type.
    pub machine: Option<String>,
    /// Machine serial number.
    pub serial_number: Option<String>,
    /// Who measured.
    pub operator: Option<String>,
    /// When the test started.
    pub date: Option<TestDate>,
    /// When the test ended, if the file records it.
    pub end_date: Option<TestDate>,
    /// Where.
    pub location: Option<String>,
    /// Title or free description.
    pub description: Option<String>,
    /// The file the measurement was read from.
    pub source_file: Option<PathBuf>,
    /// Its format.
    pub source_format: Option<SourceFormat>,
    /// The length unit the file was written in (values are converted to mm on reading).
    pub length_unit: LengthUnit,
    /// Format-specific fields kept verbatim for the report (software version, flags, PV names).
    pub extra: Vec<(String, String)>,
    /// Where the axis name came from (default: not recorded).
    pub axis_source: AxisSource,
    /// The instrument and the test set-up, where the file records them.
    pub setup: TestSetup,
}

/// The instrument and how the test was run, as far as the file records them:
/// `None` (or empty) where it does not, never a guess. The laser's vacuum
/// wavelength is in [`Environment::vacuum_wavelength_um`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TestSetup {
    /// The measuring instrument as the file names it: a laser model, or the
    /// reference-position signal of an ecmc test.
    pub instrument: Option<String>,
    /// The instrument's serial number.
    pub instrument_serial: Option<String>,
    /// Feed between targets, mm/min.
    pub feed_mm_per_min: Option<f64>,
    /// Dwell at each target, s.
    pub dwell_s: Option<f64>,
    /// Where the measuring line ran: the positions of the other axes during
    /// the test, (axis name, mm), in the file's order.
    pub other_axes_mm: Vec<(String, f64)>,
}

impl TestSetup {
    /// Whether the file recorded nothing of it.
    pub fn is_empty(&self) -> bool {
        *self == TestSetup::default()
    }
}

impl Metadata {
    /// Whether the file records that a laser interferometer measured the
    /// test: a Renishaw `.rtl` (written only by its laser software), an API
    /// `.pos` whose title names the laser. An ecmc test (a triangulation
    /// sensor or an encoder, its `REF_PV`) and axcomp's CSV do not: their
    /// uncertainty needs the user's equipment.
    pub fn records_laser_interferometer(&self) -> bool {
        match self.source_format {
            Some(SourceFormat::Rtl) => true,
            Some(SourceFormat::ApiPos) => self
                .setup
                .instrument
                .as_ref()
                .is_some_and(|name| name.to_ascii_lowercase().contains("laser")),
            Some(SourceFormat::Ecmc | SourceFormat::Csv) | None => false,
        }
    }

    /// Duration of the test, s, when both start and end are known and parsed.
    pub fn duration_s(&self) -> Option<f64> {
        let start = self.date.as_ref()?.parsed?;
        let end = self.end_date.as_ref()?.parsed?;
        let seconds = (end - start).num_seconds() as f64;
        (seconds > 0.0).then_some(seconds)
    }
}

//! File formats and pipes: which format a path or `-` means, reading standard input, writing
//! standard output, and the flags that pick one curve out of a DXF, IGES or SVG file.

use std::io::{Read as _, Write as _};
use std::path::{Path, PathBuf};

use anyhow::anyhow;
use batten::io::{self, Format, Input, Pick, ReadOptions};
use clap::{Args, ValueEnum};

use crate::failure::Failure;

/// The name standard input and output go by in messages.
pub const STDIN_NAME: &str = "<stdin>";

/// `--format`: the format of `-` or of a file name without a known extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FormatName {
    /// One x,y per line
    Csv,
    /// batten's JSON (points or a B-spline)
    Json,
    /// DXF (LWPOLYLINE, POLYLINE, SPLINE)
    Dxf,
    /// SVG (path, polyline, polygon)
    Svg,
    /// IGES (entities 126 and 106)
    Igs,
}

impl From<FormatName> for Format {
    fn from(f: FormatName) -> Format {
        match f {
            FormatName::Csv => Format::Text,
            FormatName::Json => Format::Json,
            FormatName::Dxf => Format::Dxf,
            FormatName::Svg => Format::Svg,
            FormatName::Igs => Format::Iges,
        }
    }
}

/// Flags that choose the curve in a file that holds several, and the format of pipes.
#[derive(Debug, Args, Default)]
pub struct PickArgs {
    /// Format of `-` (standard input or output) or of a file name without a known
    /// extension [default for `-`: csv]
    #[arg(long, value_enum, value_name = "FMT")]
    pub format: Option<FormatName>,
    /// DXF: the handle of the entity to fair (hexadecimal); IGES: its directory entry number
    #[arg(long, value_name = "HANDLE")]
    pub entity: Option<String>,
    /// DXF: the layer of the entity to fair; IGES: its level
    #[arg(long, value_name = "NAME")]
    pub layer: Option<String>,
    /// SVG: the id of the path, polyline or polygon to fair
    #[arg(long = "select", value_name = "ID")]
    pub select: Option<String>,
    /// SVG: take N points per segment of a path instead of its Bézier curve
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub sample: Option<u32>,
}

impl PickArgs {
    /// The library's [`Pick`].
    pub fn pick(&self) -> Pick {
        Pick::default()
            .with_entity(self.entity.clone())
            .with_layer(self.layer.clone())
            .with_id(self.select.clone())
            .with_sample(self.sample.map(|n| n as usize))
    }

    /// Refuse flags that do not apply to the input's format.
    ///
    /// # Errors
    /// [`Failure::usage`] naming the flag and the format it needs.
    pub fn check(&self, format: Format, name: &str) -> Result<(), Failure> {
        let cad = matches!(format, Format::Dxf | Format::Iges);
        let bad = if self.entity.is_some() && !cad {
            Some(("--entity", "a DXF or IGES"))
        } else if self.layer.is_some() && !cad {
            Some(("--layer", "a DXF or IGES"))
        } else if self.select.is_some() && format != Format::Svg {
            Some(("--select", "an SVG"))
        } else if self.sample.is_some() && format != Format::Svg {
            Some(("--sample", "an SVG"))
        } else {
            None
        };
        match bad {
            Some((flag, needs)) => Err(Failure::usage(anyhow!(
                "{name}: {flag} applies to {needs} input"
            ))),
            None => Ok(()),
        }
    }
}

/// Whether a path argument is `-` (standard input or output).
pub fn is_stdio(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The format of `path`: `--format` for `-`, else the extension, else `--format`.
///
/// # Errors
/// [`Failure::usage`] for a file name with no known extension and no `--format`.
pub fn format_of(path: &Path, given: Option<FormatName>) -> Result<Format, Failure> {
    if is_stdio(path) {
        return Ok(given.map_or(Format::Text, Format::from));
    }
    match (Format::from_path(path), given) {
        (Ok(f), _) => Ok(f),
        (Err(_), Some(g)) => Ok(g.into()),
        (Err(e), None) => Err(Failure::usage(e)),
    }
}

/// The name of the input in messages.
pub fn display_name(path: &Path) -> PathBuf {
    if is_stdio(path) {
        PathBuf::from(STDIN_NAME)
    } else {
        path.to_path_buf()
    }
}

/// Read the input (a file, or standard input for `-`) in `format`.
///
/// # Errors
/// [`Failure::usage`] with the library's message (file, place, problem).
pub fn read_input(
    path: &Path,
    format: Format,
    closed: bool,
    pick: &Pick,
) -> Result<Input, Failure> {
    let options = ReadOptions::default().with_closed(closed);
    if is_stdio(path) {
        let mut bytes = Vec::new();
        std::io::stdin()
            .lock()
            .read_to_end(&mut bytes)
            .map_err(|e| Failure::usage(anyhow!("{STDIN_NAME}: cannot read: {e}")))?;
        io::parse_input(&bytes, format, Path::new(STDIN_NAME), &options, pick)
            .map_err(Failure::usage)
    } else {
        io::read_input(path, Some(format), &options, pick).map_err(Failure::usage)
    }
}

/// Write `bytes` to `path` atomically, or to standard output for `-`.
///
/// # Errors
/// [`Failure::failed`] when the write fails (a closed pipe is not a failure).
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    if is_stdio(path) {
        let mut out = std::io::stdout().lock();
        return match out.write_all(bytes).and_then(|()| out.flush()) {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
            Err(e) => Err(Failure::failed(anyhow!(
                "cannot write to standard output: {e}"
            ))),
        };
    }
    io::write_atomic(path, bytes).map_err(Failure::failed)
}

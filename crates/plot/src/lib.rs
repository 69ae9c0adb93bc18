//! Every plot the product draws (the pour plot, the fit's, the analyses' figures, the accuracy
//! diagram) is drawn and written here, one way: the embedded font registered once, an RGB
//! bitmap in memory, the PNG encoded from it, and the file written all or nothing through
//! [`PendingFile`]. What each plot shows stays with its module, which draws on the [`Canvas`]
//! it is handed with the [`plotters`] vocabulary re-exported here.
//!
//! ```no_run
//! use sake_glug_plot::plotters::prelude::*;
//! use sake_glug_plot::Plot;
//!
//! const SQUARE: Plot = Plot::new("square", (200, 200));
//! SQUARE
//!     .write(std::path::Path::new("square.png"), |root| {
//!         root.fill(&WHITE).map_err(|error| error.to_string())
//!     })
//!     .unwrap();
//! ```

use std::fmt::Display;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use image::codecs::png::PngEncoder;
use image::{ColorType, ImageEncoder};
use plotters::coord::Shift;
use plotters::prelude::{BitMapBackend, DrawingArea, FontStyle, IntoDrawingArea};
use sake_glug_io::text::printable;
use sake_glug_io::{PendingFile, WriteError};

pub use plotters;

/// The font family every plot names; the embedded font is registered under it.
pub const FONT: &str = "sans-serif";

/// Where a plot draws: an RGB bitmap in memory, as large as its [`Plot::size_px`].
pub type Canvas<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// A kind of plot: its name in messages and its size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Plot {
    /// What it is called in an error ("pour plot").
    pub name: &'static str,
    /// Width and height in pixels.
    pub size_px: (u32, u32),
}

/// Why a plot could not be drawn or written. Nothing is left at its path.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The font compiled into the program could not be registered.
    #[error(
        "could not draw the {plot} {}: the embedded font did not load",
        shown(path)
    )]
    Font {
        /// The plot's name.
        plot: &'static str,
        /// The plot asked for.
        path: PathBuf,
    },
    /// Drawing failed: what plotters (or the drawing code) reported.
    #[error("could not draw the {plot} {}: {}", shown(path), printable(message))]
    Draw {
        /// The plot's name.
        plot: &'static str,
        /// The plot asked for.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The file could not be written.
    #[error("cannot write {}: {source}", shown(path))]
    Write {
        /// The plot asked for.
        path: PathBuf,
        /// What the file system said.
        source: io::Error,
    },
}

impl From<WriteError> for PlotError {
    fn from(error: WriteError) -> Self {
        Self::Write {
            path: error.path,
            source: error.source,
        }
    }
}

impl PlotError {
    /// The path the error names.
    pub fn path(&self) -> &Path {
        match self {
            Self::Font { path, .. } | Self::Draw { path, .. } | Self::Write { path, .. } => path,
        }
    }
}

/// A path as messages show it, control characters escaped.
fn shown(path: &Path) -> String {
    printable(&path.display().to_string()).into_owned()
}

/// Registers the embedded font under [`FONT`], once for the whole process: plotters keeps its
/// fonts in one global table, so every plot of every crate finds it there.
fn font_registered() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT)
            .is_ok()
    })
}

impl Plot {
    /// A plot called `name` (in messages) of `size_px` pixels.
    pub const fn new(name: &'static str, size_px: (u32, u32)) -> Self {
        Self { name, size_px }
    }

    /// The bytes its bitmap takes while it is drawn (RGB); the PNG is written from it as it is
    /// encoded.
    pub const fn bitmap_bytes(&self) -> u64 {
        self.size_px.0 as u64 * self.size_px.1 as u64 * 3
    }

    /// Draws the plot with `draw` and returns its PNG. `path` is the file it is for, which an
    /// error names.
    pub fn png<E: Display>(
        &self,
        path: &Path,
        draw: impl FnOnce(&Canvas<'_>) -> Result<(), E>,
    ) -> Result<Vec<u8>, PlotError> {
        let mut png = Vec::new();
        self.draw_png(path, draw, &mut png)?;
        Ok(png)
    }

    /// Draws the plot with `draw` into `file`'s temporary file, which its caller commits with
    /// the other files of its set.
    pub fn draw_into<E: Display>(
        &self,
        file: &PendingFile,
        draw: impl FnOnce(&Canvas<'_>) -> Result<(), E>,
    ) -> Result<(), PlotError> {
        let path = file.path();
        let mut writer = file.writer().map_err(write_error(path))?;
        self.draw_png(path, draw, &mut writer)?;
        writer.flush().map_err(write_error(path))
    }

    /// Draws the plot with `draw` and writes it to `path`, all or nothing: a failure leaves
    /// whatever was at `path` as it was, and no temporary file.
    pub fn write<E: Display>(
        &self,
        path: &Path,
        draw: impl FnOnce(&Canvas<'_>) -> Result<(), E>,
    ) -> Result<(), PlotError> {
        let file = PendingFile::beside(path, ".png").map_err(write_error(path))?;
        self.draw_into(&file, draw)?;
        PendingFile::commit_all(vec![file])?;
        Ok(())
    }

    /// Draws into a bitmap in memory, then encodes it as a PNG into `out`.
    fn draw_png<E: Display>(
        &self,
        path: &Path,
        draw: impl FnOnce(&Canvas<'_>) -> Result<(), E>,
        out: &mut impl Write,
    ) -> Result<(), PlotError> {
        let draw_error = |message: &dyn Display| PlotError::Draw {
            plot: self.name,
            path: path.to_owned(),
            message: message.to_string(),
        };
        if !font_registered() {
            return Err(PlotError::Font {
                plot: self.name,
                path: path.to_owned(),
            });
        }
        let (width, height) = self.size_px;
        let mut bitmap = vec![0u8; self.bitmap_bytes() as usize];
        {
            let root = BitMapBackend::with_buffer(&mut bitmap, self.size_px).into_drawing_area();
            draw(&root).map_err(|error| draw_error(&error))?;
            root.present().map_err(|error| draw_error(&error))?;
        }
        PngEncoder::new(out)
            .write_image(&bitmap, width, height, ColorType::Rgb8)
            .map_err(|error| match error {
                image::ImageError::IoError(source) => PlotError::Write {
                    path: path.to_owned(),
                    source,
                },
                other => draw_error(&other),
            })
    }
}

fn write_error(path: &Path) -> impl FnOnce(io::Error) -> PlotError + '_ {
    move |source| PlotError::Write {
        path: path.to_owned(),
        source,
    }
}

#[cfg(test)]
mod tests {
    use super::plotters::prelude::*;
    use super::*;

    const SMALL: Plot = Plot::new("test plot", (120, 80));

    fn text_plot(root: &Canvas<'_>) -> Result<(), String> {
        let fail = |error: &dyn Display| error.to_string();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        root.draw(&Text::new("glug", (10, 30), (FONT, 24).into_font()))
            .map_err(|e| fail(&e))
    }

    /// A PNG of the plot's size, with the embedded font's text in it (a plot without a font
    /// draws nothing but the white).
    #[test]
    fn a_plot_is_a_png_of_its_size_with_its_text() {
        let png = SMALL.png(Path::new("x.png"), text_plot).unwrap();
        let image = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), SMALL.size_px);
        let dark = image.pixels().filter(|pixel| pixel.0[0] < 128).count();
        assert!(dark > 20, "{dark} dark pixels: no text drawn");
    }

    /// Plots drawn at once from many threads (the font registered by whichever comes first)
    /// are the same bytes as one drawn alone.
    #[test]
    fn plots_drawn_at_once_are_the_same_bytes() {
        let alone = SMALL.png(Path::new("x.png"), text_plot).unwrap();
        let drawn: Vec<Vec<u8>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..8)
                .map(|_| scope.spawn(|| SMALL.png(Path::new("x.png"), text_plot).unwrap()))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(drawn.iter().all(|png| *png == alone));
    }

    /// A drawing that fails leaves the file that was there, and no temporary file; one that
    /// succeeds replaces it.
    #[test]
    fn a_plot_is_written_all_or_nothing() {
        let folder = tempfile::tempdir().unwrap();
        let path = folder.path().join("plot.png");
        std::fs::write(&path, b"the old plot").unwrap();
        let error = SMALL
            .write(&path, |root| {
                root.fill(&WHITE).map_err(|e| e.to_string())?;
                Err("it broke halfway".to_string())
            })
            .unwrap_err();
        assert!(matches!(error, PlotError::Draw { .. }), "{error:?}");
        assert!(error.to_string().contains("it broke halfway"), "{error}");
        assert_eq!(std::fs::read(&path).unwrap(), b"the old plot");
        let names = |folder: &Path| -> Vec<String> {
            std::fs::read_dir(folder)
                .unwrap()
                .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        };
        assert_eq!(names(folder.path()), ["plot.png"]);
        SMALL.write(&path, text_plot).unwrap();
        assert!(std::fs::read(&path).unwrap().starts_with(b"\x89PNG"));
        assert_eq!(names(folder.path()), ["plot.png"]);
        // A folder in the plot's place is refused before anything is drawn.
        let error = SMALL.write(folder.path(), text_plot).unwrap_err();
        assert!(matches!(error, PlotError::Write { .. }), "{error:?}");
    }

    /// A path with control characters is shown escaped.
    #[test]
    fn an_error_shows_its_path_escaped() {
        let error = SMALL
            .png(Path::new("bad\x1b[31m.png"), |_| Err("no"))
            .unwrap_err();
        assert!(!error.to_string().contains('\x1b'), "{error}");
    }
}

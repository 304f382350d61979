//! Subcommand implementations. Each module defines its clap arguments and a `run` that returns
//! the process exit code; errors become one line on stderr and exit code 2 (see `main.rs`).

pub mod check;
pub mod compare;
pub mod export;
pub mod info;
pub mod render;
pub mod tessellate;

/// Runs `build` (a scene's patch build) with a spinner on stderr naming the library's current
/// step ([`apatch::progress`]); on a terminal only (indicatif hides it otherwise), and gone,
/// with its sink, when `build` returns.
pub fn with_progress<T>(build: impl FnOnce() -> T) -> T {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let shown = bar.clone();
    apatch::progress::set_sink(Some(Box::new(move |msg: &str| {
        shown.set_message(msg.to_string());
    })));
    let out = build();
    apatch::progress::set_sink(None);
    bar.finish_and_clear();
    out
}

/// The `--width`, `--height` and `--spp` flags shared by `render` and `export mitsuba`: each
/// replaces the scene's value when given.
#[derive(clap::Args, Debug)]
pub struct FilmArgs {
    /// Image width in pixels (default: the scene's).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (default: the scene's).
    #[arg(long)]
    pub height: Option<u32>,
    /// Samples per pixel (default: the scene's).
    #[arg(long)]
    pub spp: Option<u32>,
}

impl FilmArgs {
    /// Applies the flags to a scene's settings ([`override_film`]).
    ///
    /// # Errors
    /// A size the camera rejects, or `--spp 0`.
    pub fn apply(&self, s: &mut apatch::trace::RenderSettings) -> anyhow::Result<()> {
        override_film(s, self.width, self.height, self.spp)
    }
}

/// Applies the `--width`, `--height` and `--spp` flags shared by `render` and `export mitsuba`
/// to a scene's settings (the size through `Camera::resized`).
///
/// # Errors
/// A size the camera rejects, or `--spp 0`.
pub fn override_film(
    s: &mut apatch::trace::RenderSettings,
    width: Option<u32>,
    height: Option<u32>,
    spp: Option<u32>,
) -> anyhow::Result<()> {
    if width.is_some() || height.is_some() {
        let w = width.unwrap_or(s.camera.width);
        let h = height.unwrap_or(s.camera.height);
        s.camera = s
            .camera
            .resized(w, h)
            .map_err(|e| anyhow::anyhow!("--width/--height: {e}"))?;
    }
    if let Some(spp) = spp {
        if spp == 0 {
            anyhow::bail!("--spp: must be ≥ 1");
        }
        s.spp = spp;
    }
    Ok(())
}

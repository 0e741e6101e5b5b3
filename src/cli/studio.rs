//! `gaitfit studio`: the papers' interactive editing as a local web page (see
//! [`crate::studio`]).
use crate::studio::server::{run as serve, StudioConfig, DEFAULT_PORT};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit studio`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Edit runs and walks live in a local web page (127.0.0.1 only)",
    long_about = "Serves the studio page on 127.0.0.1: pick RUNNER, KLAW or Ko-Badler, move the \
parameters (with the papers' locks) and attributes, add per-step changes, watch the figure in a \
sagittal and an orbitable 3-D view beside the relations' plots, and download the motion (BVH, \
TRC, CSV, …) or its steps table. Everything the page needs is inside the binary; it fetches \
nothing from the network, and the server answers loopback peers only.",
    after_help = "Example:\n  cargo run --release -- studio        # then open the printed address"
)]
pub struct Args {
    /// TCP port on 127.0.0.1 (0 picks a free one).
    #[arg(long, default_value_t = DEFAULT_PORT)]
    pub port: u16,
    /// Folder with refitted relations (written by `gaitfit fit`), for the "refit" choice and
    /// the plots.
    #[arg(long, value_name = "DIR", default_value = "fits")]
    pub fits: PathBuf,
    /// Folder of trials tables whose points the plots show.
    #[arg(long, value_name = "DIR", default_value = "data")]
    pub data: PathBuf,
    /// Open the page in the default browser (xdg-open / open).
    #[arg(long)]
    pub open: bool,
}

/// Runs `gaitfit studio` until interrupted.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let config = StudioConfig {
        port: args.port,
        fits: args.fits.clone(),
        data: args.data.clone(),
    };
    let open = args.open;
    serve(config, |addr| {
        let url = format!("http://{addr}/");
        println!("gaitfit studio: open {url}  (Ctrl-C stops it)");
        let _ = std::io::stdout().flush();
        if open {
            open_browser(&url);
        }
    })?;
    Ok(ExitCode::SUCCESS)
}

/// Asks the desktop to open `url`; says so if it cannot (the address is printed anyway).
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(opener)
        .arg(url)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
    {
        eprintln!("gaitfit studio: could not run {opener} ({e}); open {url} yourself");
    }
}

//! A display for the soak window: the user's (`DISPLAY` or `WAYLAND_DISPLAY`), or an `Xvfb`
//! server started for the run, under which the command runs itself again.

use anyhow::{Context, Result};
use std::process::Command;

use manylight_app::window::xvfb::Xvfb;
pub use manylight_app::window::xvfb::has_display;

/// Runs this command again with `DISPLAY` set to a fresh Xvfb server and returns its exit
/// status (its output goes to this process's stdout and stderr).
pub fn rerun_under_xvfb() -> Result<std::process::ExitStatus> {
    let xvfb = Xvfb::start().map_err(anyhow::Error::msg).context(
        "no DISPLAY is set and no Xvfb server could be started: run the soak on a desktop or under \
         `xvfb-run -a manylight soak`",
    )?;
    let exe = std::env::current_exe().context("cannot find this executable to run it under Xvfb")?;
    tracing::info!("no display set: running the soak on Xvfb :{}", xvfb.display);
    let status = Command::new(exe)
        .args(std::env::args_os().skip(1))
        .env("DISPLAY", format!(":{}", xvfb.display))
        .status()
        .context("cannot run the soak under Xvfb")?;
    drop(xvfb);
    Ok(status)
}

//! A display for the soak window: the user's (`DISPLAY` or `WAYLAND_DISPLAY`), or an `Xvfb`
//! server started for the run, under which the command runs itself again.

use anyhow::{Context, Result, bail};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// True when a window can be opened on the user's display.
pub fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()))
}

/// An Xvfb server this process started; stopped on drop.
pub struct Xvfb {
    child: Child,
    /// The display number (`:N`).
    pub display: u32,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        // SIGTERM lets Xvfb remove its socket and lock file; SIGKILL only if it does not stop.
        let _ = Command::new("kill").args(["-TERM", &self.child.id().to_string()]).status();
        let deadline = Instant::now() + Duration::from_secs(3);
        while Instant::now() < deadline && !matches!(self.child.try_wait(), Ok(Some(_))) {
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `Xvfb :N` on the first free display number from 90.
pub fn start_xvfb() -> Result<Xvfb> {
    for display in 90..140u32 {
        let socket = PathBuf::from(format!("/tmp/.X11-unix/X{display}"));
        if socket.exists() || PathBuf::from(format!("/tmp/.X{display}-lock")).exists() {
            continue;
        }
        let mut child = Command::new("Xvfb")
            .arg(format!(":{display}"))
            .args(["-screen", "0", "1280x1024x24", "-nolisten", "tcp"])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .context("cannot run Xvfb (package xvfb)")?;
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(10) {
            if socket.exists() {
                return Ok(Xvfb { child, display });
            }
            if let Ok(Some(_)) = child.try_wait() {
                break; // lost a race for this display number: try the next one
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = child.kill();
        let _ = child.wait();
    }
    bail!("Xvfb did not start on any display from :90 to :139")
}

/// Runs this command again with `DISPLAY` set to a fresh Xvfb server and returns its exit
/// status (its output goes to this process's stdout and stderr).
pub fn rerun_under_xvfb() -> Result<std::process::ExitStatus> {
    let xvfb = start_xvfb().context(
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

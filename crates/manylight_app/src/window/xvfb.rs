//! A virtual X display for windows on machines without one: an `Xvfb` server started for the
//! process (the soak command and the window test use it on headless CI machines).

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// True when a window can be opened on the user's display (`DISPLAY` or `WAYLAND_DISPLAY`).
pub fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()))
}

/// An Xvfb server this process started; stopped on drop.
pub struct Xvfb {
    child: Child,
    /// The display number (`:N`).
    pub display: u32,
}

impl Xvfb {
    /// Starts `Xvfb :N` (1280×1024×24, no TCP) on the first free display number from 90;
    /// `Err` says why none could be started (not installed, every number taken).
    pub fn start() -> Result<Xvfb, String> {
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
                .map_err(|e| format!("cannot run Xvfb (package xvfb): {e}"))?;
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
        Err("Xvfb did not start on any display from :90 to :139".into())
    }

    /// The server's process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }
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
        let _ = std::fs::remove_file(format!("/tmp/.X11-unix/X{}", self.display));
        let _ = std::fs::remove_file(format!("/tmp/.X{}-lock", self.display));
    }
}

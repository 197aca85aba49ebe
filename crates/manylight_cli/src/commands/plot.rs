//! What `plot` does: reads a CSV that `bench`, `report` or `post` wrote and draws its figures
//! as PNG files into a folder.

use crate::plot;
use anyhow::{Context, Result};
use std::path::PathBuf;

/// `plot`: draws the figures of the CSV file `csv` into the folder `out`.
pub(crate) fn run(csv: PathBuf, out: PathBuf) -> Result<()> {
    let text = std::fs::read_to_string(&csv).with_context(|| format!("cannot read {}", csv.display()))?;
    for figure in plot::figures(&text, &out).with_context(|| format!("{}", csv.display()))? {
        eprintln!("wrote {}", figure.display());
    }
    Ok(())
}

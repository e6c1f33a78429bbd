//! `polhode plot LOG.mcap`: charts of one run from its log.

use super::{EXIT_BAD_INPUT, report_files};
use std::path::{Path, PathBuf};

/// Writes the charts of the run logged in `log` into `out` (default `<stem>-plots` beside it),
/// a directory that is new, empty or polhode's (docs/cli.md).
pub(super) fn plot_cmd(log: &Path, out: Option<PathBuf>, quiet: bool) -> i32 {
    let dir = out.unwrap_or_else(|| {
        let stem = log
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "run".into());
        log.with_file_name(format!("{stem}-plots"))
    });
    if let Err(e) = crate::outputs::Plan::new()
        .input("the log", log)
        .output_dir("--out", &dir)
        .check()
    {
        eprintln!("error: {e}");
        return EXIT_BAD_INPUT;
    }
    match crate::log::charts::read(log) {
        Err(e) => {
            eprintln!("error: {e}");
            EXIT_BAD_INPUT
        }
        Ok(run) => match crate::outputs::OwnedDir::claim(&dir, &crate::log::charts::may_write) {
            Ok(owned) => report_files(crate::log::charts::write(&run, owned), quiet),
            Err(e) => {
                eprintln!("error: {e}");
                EXIT_BAD_INPUT
            }
        },
    }
}

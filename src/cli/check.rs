//! `polhode check`: validation without a run.

use super::summary::{hub_remainder_line, tank_spring_lines};
use super::{EXIT_BAD_INPUT, load};
use crate::scenario::Overrides;
use std::path::PathBuf;

/// Validates whole files, `montecarlo:` block included (with `polhode montecarlo`'s own
/// checks and messages), without running anything.
pub(super) fn check(paths: &[PathBuf]) -> i32 {
    let mut code = 0;
    for p in paths {
        let s = match load(p, &Overrides::default()) {
            Ok(s) => s,
            Err(c) => {
                code = c;
                continue;
            }
        };
        let campaign = if s.montecarlo.is_some() {
            match crate::montecarlo::load(p, None, None) {
                Ok(prep) => format!(
                    "; montecarlo: {} runs, {} dispersions, seed {}",
                    prep.campaign.runs,
                    prep.campaign.dispersions.len(),
                    prep.campaign.seed
                ),
                Err(e) => {
                    eprintln!("error: {e}");
                    code = EXIT_BAD_INPUT;
                    continue;
                }
            }
        } else {
            String::new()
        };
        println!(
            "{}: ok ({}; {}; {}; {} Hz to {}{campaign})",
            p.display(),
            s.name,
            crate::timefmt::seconds(s.duration),
            s.method.describe(),
            s.output_rate,
            s.mcap_path.display()
        );
        if let Some(line) = hub_remainder_line(&s) {
            println!("{line}");
        }
        for line in tank_spring_lines(&s) {
            println!("{line}");
        }
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
    }
    code
}

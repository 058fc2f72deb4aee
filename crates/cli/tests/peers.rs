//! The CLI's tests that need a program beside ours, as one test binary with its own harness
//! (`harness = false`, `common/peer.rs`): Mitsuba 3 (`mitsuba.rs`), Blender's `bpy`
//! (`blender.rs`) and headless Chromium (`browser.rs`). Without its peer a test is reported as
//! ignored, with the reason; `SCATTERFIT_REQUIRE_MITSUBA`, `_BLENDER` and `_CHROMIUM` = 1 make the
//! absence a failure. Each test is named after its file (`cargo test -p scatterfit --test peers
//! mitsuba::` runs the Mitsuba tests), and a peer is looked for only when one of its tests runs.

mod blender;
mod browser;
mod common;
mod mitsuba;

use std::process::ExitCode;

fn main() -> ExitCode {
    let mut trials = mitsuba::trials();
    trials.extend(blender::trials());
    trials.extend(browser::trials());
    common::peer::run(trials)
}

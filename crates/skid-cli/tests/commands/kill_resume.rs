//! Kill and resume: a run killed at any moment (SIGKILL, during the increments or while it
//! writes its outputs) leaves no output that looks complete, and `skid run --resume` continues
//! it to the outputs of the uninterrupted run, byte for byte (`summary.json` wall times aside).
//!
//! The short version of `scripts/kill-resume.py`: a shortened 2D drum case (45 increments) and
//! a shortened model file (the 2D block on a sliding ground, 20 increments), both with field
//! output every millisecond and a restart file every 2 increments, killed at seeded random
//! moments over the run; a resumed run is itself killed again at random until one finishes.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::common::{shipped, skid, without_timings};

/// A run to kill: a shipped input with the overrides that shorten it and give it field
/// output, and the name of the input as run in its directory.
struct Scenario {
    input: &'static str,
    sets: &'static [&'static str],
    as_run: &'static str,
}

/// The shipped 2D drum, shortened.
const DRUM: Scenario = Scenario {
    input: "drum/2d-analytic.json",
    sets: &["steps[1].duration=0.004", "output.field_interval=0.001"],
    as_run: "case.json",
};

/// The 2D block on a sliding ground, a model file, shortened.
const MODEL: Scenario = Scenario {
    input: "verification/2d-block-on-sliding-ground.json",
    sets: &["steps[1].duration=0.004", "output.field_interval=0.001"],
    as_run: "model.json",
};

/// `skid run` of the scenario into `out` with a restart file every 2 increments.
fn start(scenario: &Scenario, out: &Path) -> Child {
    let mut command = skid();
    command
        .arg("run")
        .arg(shipped(scenario.input))
        .arg("--out")
        .arg(out)
        .args(["--restart-every", "2"]);
    for set in scenario.sets {
        command.args(["--set", set]);
    }
    spawn(command)
}

/// `skid run --resume dir`.
fn resume(dir: &Path) -> Child {
    let mut command = skid();
    command.arg("run").arg("--resume").arg(dir);
    spawn(command)
}

fn spawn(mut command: Command) -> Child {
    command
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("skid starts")
}

/// Everything a finished run directory holds that must not depend on interruptions: every
/// file by name (`summary.json` without its wall times), the field frames included.
fn results(dir: &Path) -> Vec<(String, String)> {
    let mut files = Vec::new();
    for sub in ["", "fields"] {
        let mut names: Vec<_> = std::fs::read_dir(dir.join(sub))
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.expect("entry").path())
            .filter(|p| p.is_file())
            .collect();
        names.sort();
        for path in names {
            let name = path
                .strip_prefix(dir)
                .expect("inside")
                .display()
                .to_string();
            if name == "restart.json" {
                continue; // its wall times and statistics differ; its results are checked
            }
            let mut text = std::fs::read_to_string(&path).expect("text");
            if name == "summary.json" {
                let summary = serde_json::from_str(&text).expect("summary");
                text = without_timings(summary).to_string();
            }
            files.push((name, text));
        }
    }
    files
}

/// Where a killed run was when the kill landed, as told by what it left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Killed {
    /// Before its outputs: no history under its final name yet.
    Running,
    /// While writing its outputs: the history under its final name, no summary yet.
    InOutput,
    /// After its last output (`summary.json` is written last), while the process was exiting.
    Ended,
}

/// Checks what a killed run left in `dir`: a `summary.json` only if everything else is there
/// (the caller compares the files), otherwise no file under a final name that is not whole
/// (a history of `history_lines` lines, as the uninterrupted run's) and a restart file (if
/// any) that reads; returns where the run was when it was killed.
fn check_killed(dir: &Path, history_lines: usize) -> Killed {
    if dir.join("summary.json").exists() {
        return Killed::Ended;
    }
    if let Ok(text) = std::fs::read_to_string(dir.join("restart.json")) {
        serde_json::from_str::<Value>(&text).expect("restart.json is whole");
    }
    if let Ok(text) = std::fs::read_to_string(dir.join("fields/skid.pvd")) {
        assert!(text.trim_end().ends_with("</VTKFile>"), "skid.pvd is whole");
    }
    let history = dir.join("history.csv");
    if history.exists() {
        let text = std::fs::read_to_string(&history).expect("history");
        assert_eq!(
            text.lines().count(),
            history_lines,
            "a history.csv under its name is complete"
        );
        Killed::InOutput
    } else {
        Killed::Running
    }
}

/// A tiny seeded generator (xorshift64*), for kill moments that are random but repeatable.
struct Random(u64);

impl Random {
    /// Uniform in [0, 1).
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Waits up to `delay` for `child`; kills it if it is still running. True if it was killed.
fn kill_after(child: &mut Child, delay: Duration) -> bool {
    let deadline = Instant::now() + delay;
    while Instant::now() < deadline {
        if let Some(status) = child.try_wait().expect("wait") {
            assert!(status.success(), "skid failed: {status}");
            return false;
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    child.kill().expect("kill");
    child.wait().expect("reaped");
    true
}

/// Kills `child` as soon as `dir/history.csv` appears (the run is writing its outputs). True
/// if it was killed before it finished.
fn kill_in_output_phase(child: &mut Child, dir: &Path) -> bool {
    loop {
        if dir.join("history.csv").exists() {
            return child.kill().is_ok() && child.wait().is_ok_and(|s| !s.success());
        }
        if let Some(status) = child.try_wait().expect("wait") {
            assert!(status.success(), "skid failed: {status}");
            return false;
        }
        std::thread::sleep(Duration::from_micros(100));
    }
}

/// Resumes the run in `dir`, killing each resumed run at a random moment within `span` until
/// one finishes; returns the kills.
fn resume_to_the_end(
    dir: &Path,
    span: Duration,
    history_lines: usize,
    random: &mut Random,
) -> usize {
    let mut kills = 0;
    loop {
        let mut child = resume(dir);
        // one resumed run in two is killed, at a moment uniform over the span
        let delay = if random.next() < 0.5 {
            span.mul_f64(random.next())
        } else {
            span * 100
        };
        if !kill_after(&mut child, delay) {
            return kills;
        }
        kills += 1;
        check_killed(dir, history_lines);
    }
}

/// Kills runs of `scenario` at random moments (seeded by `seed`) until `wanted` kills over at
/// least `wanted - 1` runs, and checks that each resumes to the uninterrupted run's outputs.
fn killed_runs_resume_to_the_uninterrupted_outputs(scenario: &Scenario, wanted: usize, seed: u64) {
    let tmp = tempfile::tempdir().expect("tempdir");
    let reference = tmp.path().join("reference");
    let clock = Instant::now();
    let status = start(scenario, &reference).wait().expect("reference run");
    let span = clock.elapsed();
    assert!(status.success());
    let expected = results(&reference);
    assert!(expected.iter().any(|(name, _)| name == "fields/skid.pvd"));
    let history_lines = expected
        .iter()
        .find(|(name, _)| name == "history.csv")
        .map(|(_, text)| text.lines().count())
        .expect("history.csv");

    let mut random = Random(seed);
    let (mut kills, mut in_output) = (0, 0);
    for trial in 0..80 {
        if trial + 1 >= wanted && kills >= wanted {
            break;
        }
        let dir = tmp.path().join(format!("killed-{trial}"));
        let mut child = start(scenario, &dir);
        let killed = if trial % 6 == 5 {
            kill_in_output_phase(&mut child, &dir)
        } else {
            // a moment over the whole run, start-up and output included
            kill_after(&mut child, span.mul_f64(1.1 * random.next()))
        };
        if killed {
            kills += 1;
            in_output += usize::from(check_killed(&dir, history_lines) == Killed::InOutput);
            if !dir.join("restart.json").exists() {
                // killed before its first restart point (or before it wrote its input or made
                // its directory): nothing to resume, and saying so
                let expected_message = if !dir.is_dir() {
                    "no such directory"
                } else if !dir.join(scenario.as_run).is_file() {
                    "expected the input as run"
                } else {
                    "no restart.json"
                };
                let output = skid()
                    .arg("run")
                    .arg("--resume")
                    .arg(&dir)
                    .output()
                    .expect("skid runs");
                let message = String::from_utf8_lossy(&output.stderr);
                assert_eq!(output.status.code(), Some(2), "{message}");
                assert!(message.contains(expected_message), "{message}");
                continue;
            }
            kills += resume_to_the_end(&dir, span, history_lines, &mut random);
        }
        assert_eq!(results(&dir), expected, "trial {trial}");
    }
    eprintln!("{kills} kills, {in_output} in the output phase");
    assert!(kills >= wanted, "only {kills} kills");
    assert!(in_output >= 1, "no kill landed in the output phase");
}

#[test]
fn runs_killed_at_random_moments_resume_to_the_uninterrupted_outputs() {
    killed_runs_resume_to_the_uninterrupted_outputs(&DRUM, 25, 0x5eed_cafe_f00d_d00d);
}

#[test]
fn model_file_runs_with_fields_killed_at_random_moments_resume_alike() {
    killed_runs_resume_to_the_uninterrupted_outputs(&MODEL, 12, 0x0dd_ba11_5eed_f00d);
}

#[test]
fn resume_refuses_another_input_and_says_when_the_run_has_ended() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = tmp.path().join("run");
    assert!(start(&DRUM, &dir).wait().expect("run").success());
    let run = |args: &[&str]| {
        let output = skid().args(args).output().expect("skid runs");
        (
            output.status.code(),
            String::from_utf8_lossy(&output.stderr).into_owned(),
        )
    };
    let dir_arg = dir.to_str().expect("utf-8 path");
    let case = shipped(DRUM.input);
    let case_arg = case.to_str().expect("utf-8 path");
    // another input (the unshortened case) is refused
    let (code, message) = run(&["run", case_arg, "--resume", dir_arg]);
    assert_eq!(code, Some(2), "{message}");
    assert!(message.contains("is not the input"), "{message}");
    // the same input is accepted; the run has ended, so nothing is run again
    let mut same = vec!["run", case_arg, "--resume", dir_arg];
    for set in DRUM.sets {
        same.extend(["--set", set]);
    }
    let (code, message) = run(&same);
    assert_eq!(code, Some(0), "{message}");
    assert!(message.contains("has ended already"), "{message}");
    // an edited input as run is refused
    std::fs::remove_file(dir.join("summary.json")).expect("remove");
    let case_json = dir.join("case.json");
    let text = std::fs::read_to_string(&case_json).expect("case.json");
    std::fs::write(&case_json, text.replace("0.004", "0.005")).expect("edit");
    let (code, message) = run(&["run", "--resume", dir_arg]);
    assert_eq!(code, Some(2), "{message}");
    assert!(message.contains("has changed since"), "{message}");
    // the input restored, but the history written so far deleted
    std::fs::write(&case_json, text).expect("restore");
    std::fs::remove_file(dir.join("history.csv")).expect("remove");
    let (code, message) = run(&["run", "--resume", dir_arg]);
    assert_eq!(code, Some(2), "{message}");
    assert!(
        message.contains("history.csv") && message.contains("missing or has changed"),
        "{message}"
    );
    // a directory that holds no run
    let (code, message) = run(&["run", "--resume", tmp.path().to_str().expect("utf-8")]);
    assert_eq!(code, Some(2), "{message}");
    assert!(message.contains("expected the input as run"), "{message}");
}

//! Sweeps and shards: the shipped sweep (12 runs of friction x pressure on 2d-analytic,
//! shortened here) run as one batch and as 3 shards merges into the same sweep report, byte for
//! byte; every run directory holds its parameters.json; `--shard slurm` takes the shard from
//! the Slurm job array task and refuses to guess outside one.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn skid(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skid"))
        .args(args)
        .output()
        .expect("skid runs")
}

/// The shipped sweep with its base made absolute and its runs shortened: a drum at 3 rad/s
/// stops within 13 ms at the lowest friction and pressure, and the spin-down lasts 15 ms.
fn short_sweep(dir: &Path) -> PathBuf {
    let shipped = repo("cases/sweeps/2d-friction-pressure.json");
    let mut sweep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&shipped).expect("shipped sweep"))
            .expect("json");
    sweep["base"] = repo("cases/drum/2d-analytic.json")
        .display()
        .to_string()
        .into();
    sweep["set"] = serde_json::json!(["drum.omega0=3", "steps[1].duration=0.015"]);
    let path = dir.join("2d-friction-pressure.json");
    std::fs::write(&path, sweep.to_string()).expect("write sweep");
    path
}

fn batch_names(dir: &Path) -> Vec<String> {
    let batch: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(dir.join("batch.json")).expect("batch.json"))
            .expect("json");
    batch
        .iter()
        .map(|e| e["name"].as_str().expect("name").to_string())
        .collect()
}

#[test]
fn a_sweep_run_as_three_shards_merges_into_the_report_of_one_batch() {
    let root = tempfile::tempdir().expect("tempdir");
    let sweep = short_sweep(root.path());
    let one = root.path().join("one");
    let out = skid(&[
        "batch".as_ref(),
        sweep.as_os_str(),
        "--jobs".as_ref(),
        "1".as_ref(),
        "--out".as_ref(),
        one.as_os_str(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names = batch_names(&one);
    let expected: Vec<String> = (1..=12)
        .map(|i| format!("2d-friction-pressure-{i:02}"))
        .collect();
    assert_eq!(names, expected);
    let parameters: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(one.join("2d-friction-pressure-06/parameters.json"))
            .expect("parameters.json"),
    )
    .expect("json");
    assert_eq!(parameters["index"], 6);
    assert_eq!(parameters["parameters"][0]["field"], "contact.mu");
    assert_eq!(parameters["parameters"][0]["value"], 0.15);
    assert_eq!(parameters["parameters"][1]["value"], 300000.0);
    let case: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(one.join("2d-friction-pressure-06/case.json")).expect("case.json"),
    )
    .expect("json");
    assert_eq!(case["contact"]["mu"], 0.15);
    assert_eq!(case["back_plate"]["pressure"], 300000.0);
    assert_eq!(case["drum"]["omega0"], 3.0);

    let mut shards = Vec::new();
    for i in 1..=3 {
        let dir = root.path().join(format!("shard-{i}"));
        let shard = format!("{i}/3");
        let out = skid(&[
            "batch".as_ref(),
            sweep.as_os_str(),
            "--jobs".as_ref(),
            "1".as_ref(),
            "--shard".as_ref(),
            shard.as_ref(),
            "--out".as_ref(),
            dir.as_os_str(),
        ]);
        assert_eq!(out.status.code(), Some(0));
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(stdout.contains("4 of 4 cases (shard "), "{stdout}");
        let expected: Vec<String> = (0..4)
            .map(|k| format!("2d-friction-pressure-{:02}", 3 * k + i))
            .collect();
        assert_eq!(batch_names(&dir), expected);
        shards.push(dir);
    }

    let single_md = root.path().join("single.md");
    let out = skid(&[
        "report".as_ref(),
        "--sweep".as_ref(),
        one.as_os_str(),
        "--out".as_ref(),
        single_md.as_os_str(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains("12 runs of 1 sweeps, 0 missing"));
    let merged_md = root.path().join("merged.md");
    let out = skid(&[
        "report".as_ref(),
        "--sweep".as_ref(),
        shards[2].as_os_str(),
        shards[0].as_os_str(),
        shards[1].as_os_str(),
        "--out".as_ref(),
        merged_md.as_os_str(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let single = std::fs::read_to_string(&single_md).expect("single report");
    let merged = std::fs::read_to_string(&merged_md).expect("merged report");
    assert_eq!(merged, single);
    assert_eq!(single.matches("| completed |").count(), 12, "{single}");
    assert!(!single.contains("| n/a |"), "every run stops: {single}");

    let partial_md = root.path().join("partial.md");
    let out = skid(&[
        "report".as_ref(),
        "--sweep".as_ref(),
        shards[0].as_os_str(),
        "--out".as_ref(),
        partial_md.as_os_str(),
    ]);
    assert_eq!(out.status.code(), Some(1), "runs missing");
    let partial = std::fs::read_to_string(&partial_md).expect("partial report");
    assert!(partial.contains("4 of 12 runs listed"), "{partial}");
    assert!(partial.contains("`2d-friction-pressure-02`"), "{partial}");
}

#[test]
fn shard_slurm_reads_the_array_task_and_refuses_outside_one() {
    let root = tempfile::tempdir().expect("tempdir");
    let sweep = short_sweep(root.path());
    let dir = root.path().join("task");
    let run = |vars: &[(&str, &str)]| {
        let mut command = Command::new(env!("CARGO_BIN_EXE_skid"));
        command
            .arg("batch")
            .arg(&sweep)
            .args(["--shard", "slurm", "--jobs", "1", "--out"])
            .arg(&dir)
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("SLURM_ARRAY_TASK_MIN")
            .env_remove("SLURM_ARRAY_TASK_MAX")
            .env_remove("SLURM_ARRAY_TASK_COUNT");
        command.envs(vars.iter().copied());
        command.output().expect("skid runs")
    };
    let outside = run(&[]);
    assert_eq!(outside.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&outside.stderr);
    assert!(
        stderr.contains("SLURM_ARRAY_TASK_ID is not set"),
        "{stderr}"
    );
    assert!(!dir.exists(), "nothing run");
    let task = run(&[
        ("SLURM_ARRAY_TASK_ID", "11"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "11"),
        ("SLURM_ARRAY_TASK_COUNT", "12"),
    ]);
    assert_eq!(
        task.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&task.stderr)
    );
    assert_eq!(batch_names(&dir), ["2d-friction-pressure-12"]);
    let bad = skid(&[
        "batch".as_ref(),
        sweep.as_os_str(),
        "--shard".as_ref(),
        "4/3".as_ref(),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--shard: expected a shard I/N"));
}

//! `rubber-atlas run` and `merge` end to end, through the binary: bad scenes are refused with
//! one line and nothing written; 1 and 2 threads give identical arrays; a run killed with
//! SIGKILL at several points and resumed equals an uninterrupted run bit for bit and
//! recomputes no finished unit; three shards merged equal a single run bit for bit.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_rubber-atlas");

fn scene_text(name: &str, method: &str, grid: &str) -> String {
    format!(
        r#"name = "{name}"
[body]
nu = 0.5
eta = 0.5
[axes]
{grid}
[solver]
tolerance = 1e-8
method = "{method}"
"#
    )
}

/// A small quadrature scene: 2 × 2 slices of 24 × 40 cells over both diagram sides.
fn small_scene(dir: &Path) -> PathBuf {
    let path = dir.join("small.toml");
    std::fs::write(
        &path,
        scene_text(
            "small",
            "quadrature",
            "alpha = [0.2, 0.5]\nbeta = [0.8, 3.0]\n\
             kappa = { start = 0.0, stop = 1.5, num = 24 }\n\
             energy = { start = 0.5, stop = 4.0, num = 40 }",
        ),
    )
    .unwrap();
    path
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

fn ok(output: &Output) -> String {
    assert!(
        output.status.success(),
        "exit {:?}: {}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Every dataset of an atlas file as raw bytes, by name.
fn arrays(path: &Path) -> Vec<(String, Vec<u8>)> {
    let file = crate::h5(path, crate::H5::Read);
    let mut out = Vec::new();
    for name in file.member_names().unwrap() {
        let ds = file.dataset(&name).unwrap();
        let dtype = ds.dtype().unwrap();
        let bytes: Vec<u8> = if dtype.is::<f64>() {
            ds.read_raw::<f64>()
                .unwrap()
                .iter()
                .flat_map(|x| x.to_bits().to_le_bytes())
                .collect()
        } else if dtype.is::<u8>() {
            ds.read_raw::<u8>().unwrap()
        } else if dtype.is::<i32>() {
            ds.read_raw::<i32>()
                .unwrap()
                .iter()
                .flat_map(|x| x.to_le_bytes())
                .collect()
        } else {
            panic!("unexpected type of {name}");
        };
        out.push((name, bytes));
    }
    out.sort();
    out
}

/// Value `i` of the scene axis `{ start, stop, num }` (docs/scenes.md: the last exactly `stop`).
fn axis_value(start: f64, stop: f64, num: usize, i: usize) -> f64 {
    if i + 1 == num {
        stop
    } else {
        start + (stop - start) / (num - 1) as f64 * i as f64
    }
}

fn assert_same_arrays(a: &Path, b: &Path) {
    let (x, y) = (arrays(a), arrays(b));
    let names = |v: &[(String, Vec<u8>)]| v.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&x), names(&y));
    for ((name, p), (_, q)) in x.iter().zip(&y) {
        assert!(p == q, "{name} differs between {a:?} and {b:?}");
    }
}

#[test]
fn bad_scenes_are_refused_with_one_line_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read_to_string(small_scene(dir.path())).unwrap();
    let cases: [(&str, &str, &str); 8] = [
        ("nu = 0.5", "nu = 0.5\ncolour = 1", "body.colour"),
        ("eta = 0.5", "eta = \"big\"", "body.eta"),
        ("alpha = [0.2, 0.5]", "alpha = []", "axes.alpha"),
        (
            "start = 0.0, stop = 1.5",
            "start = 1.5, stop = 0.0",
            "axes.kappa",
        ),
        ("alpha = [0.2, 0.5]", "alpha = [0.2, 1.5]", "axes.alpha"),
        ("tolerance = 1e-8", "tolerance = 2.0", "solver.tolerance"),
        (
            "method = \"quadrature\"",
            "method = \"rk4\"",
            "solver.method",
        ),
        ("num = 40", "num = 0", "axes.energy.num"),
    ];
    for (from, to, key) in cases {
        let path = dir.path().join("bad.toml");
        assert!(good.contains(from));
        std::fs::write(&path, good.replacen(from, to, 1)).unwrap();
        let out = dir.path().join("bad.h5");
        let output = run(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{to}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("bad.toml") && stderr.contains(key),
            "{key}: {stderr}"
        );
        assert!(!stderr.contains("panicked"));
        let left = files_named(dir.path(), "bad.h5");
        assert!(left.is_empty(), "{to}: left {left:?}");
    }
}

/// The names in `dir` that start with `prefix` (an output and whatever a run leaves beside it).
fn files_named(dir: &Path, prefix: &str) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(prefix))
        .collect()
}

#[test]
fn an_existing_output_is_kept_without_force_and_threads_do_not_change_a_bit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let (one, two) = (dir.path().join("one.h5"), dir.path().join("two.h5"));
    let s = scene.to_str().unwrap();
    ok(&run(&[
        "run",
        s,
        "--out",
        one.to_str().unwrap(),
        "--threads",
        "1",
    ]));
    let summary = ok(&run(&[
        "run",
        s,
        "--out",
        two.to_str().unwrap(),
        "--threads",
        "2",
    ]));
    assert!(summary.contains("cells: 3840"), "{summary}");
    assert_same_arrays(&one, &two);

    let before = std::fs::read(&one).unwrap();
    let again = run(&["run", s, "--out", one.to_str().unwrap()]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
    assert_eq!(std::fs::read(&one).unwrap(), before);
    ok(&run(&[
        "run",
        s,
        "--out",
        one.to_str().unwrap(),
        "--force",
        "--quiet",
    ]));
    assert_same_arrays(&one, &two);
}

#[test]
fn atlas_values_equal_the_cell_command() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let out = dir.path().join("a.h5");
    ok(&run(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]));
    let file = crate::h5(&out, crate::H5::Read);
    let n = file
        .dataset("rotation_number")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    let count = file
        .dataset("n_components")
        .unwrap()
        .read_raw::<u8>()
        .unwrap();
    // The component axis is laid out by family (the default): the slot of each family.
    let labels = file.dataset("component").unwrap().read_raw::<u8>().unwrap();
    let slots = labels.len();
    let families = ["well_0", "well_pi", "well_equator", "over_the_top"];
    let (alphas, betas) = ([0.2, 0.5], [0.8, 3.0]);
    let kappa = |i: usize| axis_value(0.0, 1.5, 24, i);
    let energy = |j: usize| axis_value(0.5, 4.0, 40, j);
    let mut checked = 0;
    for (ia, ib, ik, ie) in [
        (0, 0, 5, 20),
        (1, 1, 12, 30),
        (1, 0, 23, 39),
        (0, 1, 0, 25),
        (1, 1, 7, 11),
    ] {
        let cell = ((ia * 2 + ib) * 24 + ik) * 40 + ie;
        let output = run(&[
            "cell",
            "--alpha",
            &alphas[ia].to_string(),
            "--beta",
            &betas[ib].to_string(),
            "--nu",
            "0.5",
            "--eta",
            "0.5",
            "--kappa",
            &format!("{:?}", kappa(ik)),
            "--energy",
            &format!("{:?}", energy(ie)),
            "--tol",
            "1e-8",
            "--json",
        ]);
        let json: serde_json::Value = serde_json::from_str(&ok(&output)).unwrap();
        let components = json["components"].as_array().unwrap();
        assert_eq!(components.len(), count[cell] as usize);
        for c in components {
            // The scene asks for no drift and `cell` computes it: the drift's convergence may
            // take the quadrature a level further, so N agrees within its estimate (equal bits
            // are not promised).
            let code = families.iter().position(|&f| c["family"] == f).unwrap() as u8;
            let slot = labels.iter().position(|&l| l == code).unwrap();
            let expected = c["rotation_number"].as_f64().unwrap();
            let estimate = c["errors"]["rotation_number"].as_f64().unwrap();
            assert!(
                (n[cell * slots + slot] - expected).abs() <= estimate,
                "cell {cell}: {} against {expected} ± {estimate}",
                n[cell * slots + slot]
            );
            checked += 1;
        }
    }
    assert!(checked >= 4);
}

/// A scene slow enough to be killed part-way: the ODE method, 6 slices of one unit each.
fn slow_scene(dir: &Path) -> PathBuf {
    let path = dir.join("slow.toml");
    std::fs::write(
        &path,
        scene_text(
            "slow",
            "ode",
            "alpha = [0.3, 0.5]\nbeta = [0.8, 2.0, 3.0]\n\
             kappa = { start = 0.05, stop = 1.5, num = 24 }\n\
             energy = { start = 1.0, stop = 4.0, num = 64 }",
        ),
    )
    .unwrap();
    path
}

fn unit_files(journal: &Path) -> usize {
    std::fs::read_dir(journal).map_or(0, |d| {
        d.filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            let name = name.to_string_lossy();
            name.starts_with("unit-") && name.ends_with(".bin")
        })
        .count()
    })
}

#[test]
fn a_run_killed_at_any_point_resumes_to_the_same_arrays() {
    let dir = tempfile::tempdir().unwrap();
    let scene = slow_scene(dir.path());
    let s = scene.to_str().unwrap();
    let reference = dir.path().join("reference.h5");
    let summary = ok(&run(&["run", s, "--out", reference.to_str().unwrap()]));
    let total_units: usize = summary
        .lines()
        .find_map(|l| l.strip_prefix("units: "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert!(total_units >= 4, "{summary}");

    // Kill after 0, 1, half and all units are in the journal (the last one while the file
    // is being written, or just before).
    let mut resumed_somewhere = false;
    for kill_after in [0, 1, total_units / 2, total_units] {
        let out = dir.path().join(format!("killed-{kill_after}.h5"));
        let journal = dir.path().join(format!("killed-{kill_after}.h5.partial.d"));
        let mut child = Command::new(BIN)
            .args(["run", s, "--out", out.to_str().unwrap(), "--quiet"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while unit_files(&journal) < kill_after
            && start.elapsed() < Duration::from_secs(60)
            && child.try_wait().unwrap().is_none()
        {
            std::thread::sleep(Duration::from_millis(2));
        }
        child.kill().unwrap(); // SIGKILL
        let status = child.wait().unwrap();
        if status.success() {
            // It finished before the kill landed: nothing to resume at this point.
            continue;
        }
        assert!(!out.exists(), "a killed run left {out:?} as if complete");
        let done = unit_files(&journal);
        eprintln!("killed after {done} of {total_units} units (asked {kill_after})");
        let resume = ok(&run(&[
            "run",
            s,
            "--out",
            out.to_str().unwrap(),
            "--resume",
        ]));
        let line = resume.lines().find(|l| l.starts_with("units: ")).unwrap();
        assert!(
            line.contains(&format!(
                "({done} resumed from an interrupted run, {} computed now)",
                total_units - done
            )),
            "after {done} units: {line}"
        );
        resumed_somewhere |= done > 0;
        // The summary counts all cells, those of the journal included.
        for prefix in ["cells: ", "components by status: "] {
            let line = |text: &str| {
                text.lines()
                    .find(|l| l.starts_with(prefix))
                    .map(str::to_owned)
            };
            assert_eq!(line(&resume), line(&summary), "{prefix}");
        }
        assert_same_arrays(&reference, &out);
        assert!(!journal.exists());
    }
    assert!(resumed_somewhere, "no kill landed part-way");

    // Without --resume or --force an interrupted run's journal is not silently thrown away.
    let out = dir.path().join("left.h5");
    let mut child = Command::new(BIN)
        .args(["run", s, "--out", out.to_str().unwrap(), "--quiet"])
        .spawn()
        .unwrap();
    let journal = dir.path().join("left.h5.partial.d");
    while unit_files(&journal) < 1 {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let again = run(&["run", s, "--out", out.to_str().unwrap()]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("--resume"));
    // The scene edited since: --resume would be refused, so it is not suggested (it was:
    // adversary pass of 2026-11-27); --update computes the new scene.
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, format!("{text}\n# edited\n")).unwrap();
    let again = run(&["run", s, "--out", out.to_str().unwrap()]);
    let message = String::from_utf8_lossy(&again.stderr);
    assert_eq!(again.status.code(), Some(2), "{message}");
    assert!(
        message.contains("of another version of this scene")
            && message.contains("--update")
            && !message.contains("--resume"),
        "{message}"
    );
    // Another scene's journal: --update refuses it as --resume does, so neither is offered.
    let other = dir.path().join("other.toml");
    std::fs::write(&other, text.replace("name = \"slow\"", "name = \"other\"")).unwrap();
    let refused = run(&[
        "run",
        other.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let message = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{message}");
    assert!(
        message.contains("of another scene (\"slow\")")
            && message.contains("--force")
            && !message.contains("--update")
            && !message.contains("--resume"),
        "{message}"
    );
    ok(&run(&[
        "run",
        s,
        "--out",
        out.to_str().unwrap(),
        "--update",
    ]));
    // An output named as a run's unfinished file is refused (open_atlas would refuse the
    // finished atlas by its name).
    let partial = dir.path().join("q.h5.partial.h5");
    let refused = run(&["run", s, "--out", partial.to_str().unwrap()]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("ends in .partial.h5"));
    assert!(!partial.exists());
}

#[test]
fn four_shards_merged_equal_a_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let s = scene.to_str().unwrap();
    let single = dir.path().join("single.h5");
    ok(&run(&[
        "run",
        s,
        "--out",
        single.to_str().unwrap(),
        "--quiet",
    ]));
    let shards: Vec<PathBuf> = (1..=4)
        .map(|i| {
            let path = dir.path().join(format!("shard-{i}.h5"));
            ok(&run(&[
                "run",
                s,
                "--out",
                path.to_str().unwrap(),
                "--shard",
                &format!("{i}/4"),
                "--quiet",
            ]));
            path
        })
        .collect();
    let merged = dir.path().join("merged.h5");
    let mut args = vec!["merge".to_string()];
    // In another order than made: the shards know their index.
    for i in [2, 0, 3, 1] {
        args.push(shards[i].to_str().unwrap().to_string());
    }
    args.extend(["--out".to_string(), merged.to_str().unwrap().to_string()]);
    let output = Command::new(BIN).args(&args).output().unwrap();
    ok(&output);
    assert_same_arrays(&single, &merged);

    // Missing parts, a duplicate, a shard of another scene: refused, nothing written.
    let refused = dir.path().join("refused.h5");
    let r = refused.to_str().unwrap();
    let missing = run(&[
        "merge",
        shards[0].to_str().unwrap(),
        shards[2].to_str().unwrap(),
        "--out",
        r,
    ]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("missing: 2/4, 4/4"));
    let twice = run(&[
        "merge",
        shards[0].to_str().unwrap(),
        shards[0].to_str().unwrap(),
        shards[2].to_str().unwrap(),
        "--out",
        r,
    ]);
    assert_eq!(twice.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&twice.stderr).contains("is named twice among the shards"));
    // The same file under another spelling of its path.
    let respelled = dir.path().join(".").join("shard-1.h5");
    let twice = run(&[
        "merge",
        shards[0].to_str().unwrap(),
        respelled.to_str().unwrap(),
        "--out",
        r,
    ]);
    assert_eq!(twice.status.code(), Some(2));
    let text = String::from_utf8_lossy(&twice.stderr);
    assert!(
        text.contains("is named twice among the shards") && text.lines().count() == 1,
        "{text}"
    );
    // A shard whose scene text was edited (adversary pass of 2026-11-28: merged, with a
    // fresh checksum, when given second; "not a shard of the same scene as itself" when
    // first): refused as damaged, in either place.
    let edited = dir.path().join("edited.h5");
    std::fs::copy(&shards[1], &edited).unwrap();
    {
        let file = hdf5::File::open_rw(&edited).unwrap();
        let text: hdf5::types::VarLenUnicode = file.attr("scene").unwrap().read_scalar().unwrap();
        let changed: hdf5::types::VarLenUnicode = format!("{text}\n# edited").parse().unwrap();
        file.attr("scene").unwrap().write_scalar(&changed).unwrap();
    }
    for order in [[0, 1], [1, 0]] {
        let paths = [shards[0].as_path(), edited.as_path()];
        let damaged = run(&[
            "merge",
            paths[order[0]].to_str().unwrap(),
            paths[order[1]].to_str().unwrap(),
            shards[2].to_str().unwrap(),
            shards[3].to_str().unwrap(),
            "--out",
            r,
        ]);
        assert_eq!(damaged.status.code(), Some(2));
        let text = String::from_utf8_lossy(&damaged.stderr);
        assert!(
            text.contains("edited.h5: is damaged") && text.lines().count() == 1,
            "{text}"
        );
        assert!(!refused.exists());
    }
    // A directory that is not a journal, and a symbolic link, where the run keeps its
    // resume journal: refused and kept, with --force too.
    let user_dir = dir.path().join("kept.h5.partial.d");
    std::fs::create_dir(&user_dir).unwrap();
    std::fs::write(user_dir.join("notes.txt"), "mine").unwrap();
    let link = dir.path().join("linked.h5.partial.d");
    std::os::unix::fs::symlink(dir.path(), &link).unwrap();
    for (name, words) in [
        (
            "kept.h5",
            "is a directory that is not a rubber-atlas resume journal",
        ),
        ("linked.h5", "is a symbolic link"),
    ] {
        let out = dir.path().join(name);
        let o = run(&[
            "run",
            s,
            "--out",
            out.to_str().unwrap(),
            "--force",
            "--quiet",
        ]);
        assert_eq!(o.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&o.stderr).contains(words));
    }
    assert_eq!(
        std::fs::read_to_string(user_dir.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(link.exists());
    // A regular file where the run keeps its resume journal: named as such, and kept, with
    // --force too.
    let blocked = dir.path().join("blocked.h5");
    let journal = dir.path().join("blocked.h5.partial.d");
    std::fs::write(&journal, "not a journal").unwrap();
    for extra in [None, Some("--force"), Some("--resume")] {
        let mut args = vec!["run", s, "--out", blocked.to_str().unwrap(), "--quiet"];
        args.extend(extra);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}");
        let text = String::from_utf8_lossy(&o.stderr);
        assert!(
            text.contains("is not a directory") && text.lines().count() == 1,
            "{text}"
        );
        assert_eq!(std::fs::read_to_string(&journal).unwrap(), "not a journal");
        assert!(!blocked.exists());
    }
    let other_scene = dir.path().join("other.toml");
    std::fs::write(
        &other_scene,
        std::fs::read_to_string(&scene)
            .unwrap()
            .replace("num = 40", "num = 41"),
    )
    .unwrap();
    let other = dir.path().join("other-2.h5");
    ok(&run(&[
        "run",
        other_scene.to_str().unwrap(),
        "--out",
        other.to_str().unwrap(),
        "--shard",
        "2/4",
        "--quiet",
    ]));
    let mixed = run(&[
        "merge",
        shards[0].to_str().unwrap(),
        other.to_str().unwrap(),
        shards[2].to_str().unwrap(),
        "--out",
        r,
    ]);
    assert_eq!(mixed.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&mixed.stderr).contains("same scene"));
    // Shards whose shard_index attributes were swapped by hand: their coordinates give them
    // away (the data would land in each other's place).
    for (i, index) in [(0usize, 2i64), (1, 1)] {
        let copy = dir.path().join(format!("swapped-{i}.h5"));
        std::fs::copy(&shards[i], &copy).unwrap();
        let f = crate::h5(&copy, crate::H5::ReadWrite);
        f.attr("shard_index").unwrap().write_scalar(&index).unwrap();
    }
    let mut swapped = vec!["merge".to_string()];
    for name in ["swapped-0.h5", "swapped-1.h5"] {
        swapped.push(dir.path().join(name).to_str().unwrap().to_string());
    }
    for i in [2, 3] {
        swapped.push(shards[i].to_str().unwrap().to_string());
    }
    swapped.extend(["--out".to_string(), r.to_string()]);
    let o = Command::new(BIN).args(&swapped).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("coordinates"));
    assert!(!refused.exists());
}

/// Issue 14 item 4: a shard file holds just its box of the grid (here half of the α values),
/// every cell of it computed and equal to a single run's, so that xarray combines the
/// shards by their coordinates.
/// A grid of tiny slices (issue 22: 1000 × 1000 one-cell slices wrote a chunk and a journal
/// file per cell, 2 kB and 200 µs a cell) is computed in units of many β: one chunk and one
/// journal file each; its shards split α and merge to the same arrays.
#[test]
fn tiny_slices_are_grouped_into_units_and_their_shards_merge() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tiny.toml");
    std::fs::write(
        &scene,
        scene_text(
            "tiny",
            "quadrature",
            "alpha = { start = 0.1, stop = 0.7, num = 3 }\n\
             beta = { start = 0.5, stop = 3.0, num = 300 }\n\
             kappa = [0.8]\nenergy = [2.0, 2.5]",
        ),
    )
    .unwrap();
    let s = scene.to_str().unwrap();
    let single = run_quietly(s, &dir.path().join("single.h5"));
    let chunks = crate::h5(&single, crate::H5::Read)
        .dataset("rotation_number")
        .unwrap()
        .chunk()
        .unwrap();
    assert_eq!(chunks[..4], [1, 300, 1, 2]);
    let shards: Vec<String> = (1..=3)
        .map(|i| {
            let path = dir.path().join(format!("tiny-{i}.h5"));
            ok(&run(&[
                "run",
                s,
                "--out",
                path.to_str().unwrap(),
                "--shard",
                &format!("{i}/3"),
                "--quiet",
            ]));
            path.to_str().unwrap().to_string()
        })
        .collect();
    // β is one group: more shards than α values are refused, in one line.
    let four = run(&["run", s, "--out", "x.h5", "--shard", "1/4"]);
    assert_eq!(four.status.code(), Some(2));
    let merged = dir.path().join("merged.h5");
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(shards.iter().map(String::as_str));
    args.extend(["--out", merged.to_str().unwrap()]);
    ok(&run(&args));
    assert_same_arrays(&single, &merged);
}

#[test]
fn a_shard_file_holds_just_its_region_equal_to_a_single_run() {
    use rubber_atlas::atlas::cell_status;
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let whole = run_quietly(scene.to_str().unwrap(), &dir.path().join("whole.h5"));
    let whole = crate::h5(&whole, crate::H5::Read);
    let read_f64 = |f: &hdf5::File, name: &str| f.dataset(name).unwrap().read_raw::<f64>().unwrap();
    let whole_alpha = read_f64(&whole, "alpha");
    let whole_n = whole
        .dataset("rotation_number")
        .unwrap()
        .read::<f64, ndarray::Ix5>()
        .unwrap();
    let mut seen = Vec::new();
    for i in 1..=2 {
        let shard = dir.path().join(format!("s{i}.h5"));
        ok(&run(&[
            "run",
            scene.to_str().unwrap(),
            "--out",
            shard.to_str().unwrap(),
            "--shard",
            &format!("{i}/2"),
            "--quiet",
        ]));
        let f = crate::h5(&shard, crate::H5::Read);
        // The scene has two alpha, two beta and one block of kappa rows: shards split alpha.
        let alpha = read_f64(&f, "alpha");
        assert_eq!(alpha.len(), 1);
        assert_eq!(read_f64(&f, "beta"), read_f64(&whole, "beta"));
        let ia = whole_alpha.iter().position(|&a| a == alpha[0]).unwrap();
        seen.push(ia);
        let status = f.dataset("cell_status").unwrap().read_raw::<u8>().unwrap();
        assert!(status.iter().all(|&s| s <= cell_status::FAILED));
        let n = f
            .dataset("rotation_number")
            .unwrap()
            .read::<f64, ndarray::Ix5>()
            .unwrap();
        let expected = whole_n.slice(ndarray::s![ia..ia + 1, .., .., .., ..]);
        assert_eq!(n.shape(), expected.shape());
        assert!(n
            .iter()
            .zip(expected.iter())
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }
    seen.sort();
    assert_eq!(seen, [0, 1]);
}

/// Runs `scene` into `out` (quietly; it must succeed) and returns `out`.
fn run_quietly(scene: &str, out: &Path) -> PathBuf {
    ok(&run(&[
        "run",
        scene,
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]));
    out.to_path_buf()
}

/// The slow scene in a fresh folder (kept while the first value lives), the path of the
/// scene, its reference run, and the output and journal paths of a run under test.
fn slow_run() -> (tempfile::TempDir, String, PathBuf, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let scene = slow_scene(dir.path()).to_str().unwrap().to_string();
    let reference = run_quietly(&scene, &dir.path().join("reference.h5"));
    let out = dir.path().join("o.h5");
    let journal = dir.path().join("o.h5.partial.d");
    (dir, scene, reference, out, journal)
}

/// Waits until the run writing `journal` has `units` unit files there (or has ended).
fn wait_for_units(child: &mut std::process::Child, journal: &Path, units: usize) {
    let start = Instant::now();
    while unit_files(journal) < units
        && start.elapsed() < Duration::from_secs(60)
        && child.try_wait().unwrap().is_none()
    {
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn two_runs_on_one_output_never_leave_a_wrong_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = slow_scene(dir.path());
    let s = scene.to_str().unwrap();
    let reference = run_quietly(s, &dir.path().join("reference.h5"));
    // The second run starts at different moments of the first (before its first unit, part
    // of the way, about when it ends), with --resume or --force.
    for (round, delay_ms) in [0u64, 20, 150, 400, 900, 0, 60, 300]
        .into_iter()
        .enumerate()
    {
        let out = dir.path().join(format!("o{round}.h5"));
        let o = out.to_str().unwrap();
        let first = Command::new(BIN)
            .args(["run", s, "--out", o, "--quiet"])
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let mode = if round % 2 == 0 {
            "--resume"
        } else {
            "--force"
        };
        let second = run(&["run", s, "--out", o, mode, "--quiet"]);
        let first = first.wait_with_output().unwrap();
        let mut succeeded = 0;
        for output in [&first, &second] {
            let text = String::from_utf8_lossy(&output.stderr);
            match output.status.code() {
                Some(0) => succeeded += 1,
                // Refused at once while the other holds the output (at delay 0 either may
                // be first).
                Some(75) => assert!(text.contains("another rubber-atlas process"), "{text}"),
                // Started after the other had finished: the output exists (--resume).
                Some(2) => assert!(text.contains("exists"), "{text}"),
                code => panic!("round {round}: a run exited {code:?}: {text}"),
            }
        }
        assert!(succeeded >= 1, "round {round}: neither run finished");
        assert_same_arrays(&reference, &out);
        for leftover in [".partial.d", ".partial.h5", ".lock"] {
            let path = dir.path().join(format!("o{round}.h5{leftover}"));
            assert!(!path.exists(), "round {round}: {path:?} left behind");
        }
    }
}

/// A run stopped while it lays out its component axis (a long census: 9 million κ-rows in
/// the θ_min layout, which counts them all) says that nothing was kept, and names no journal.
#[test]
fn a_run_stopped_before_its_first_cell_says_that_nothing_was_kept() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("census.toml");
    std::fs::write(
        &scene,
        "name = \"census\"\n[body]\nnu = 0.5\neta = 0.5\n[axes]\n\
         alpha = { start = 0.0, stop = 0.9, num = 300 }\n\
         beta = { start = 0.3, stop = 3.0, num = 300 }\n\
         kappa = { start = 0.0, stop = 2.0, num = 100 }\nenergy = [2.5]\n\
         [outputs]\nfields = [\"rotation_number\"]\nlayout = \"theta_min\"\n",
    )
    .unwrap();
    let out = dir.path().join("census.h5");
    let (output, _) = run_interrupted(&scene, &out, Duration::from_millis(500));
    let text = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{text}");
    assert!(text.contains("laying out the component axis"), "{text}");
    assert!(
        text.contains(
            "stopped by SIGINT before any cell was computed (nothing kept, nothing to resume)"
        ),
        "{text}"
    );
    assert!(!text.contains("partial.d") && !out.exists());
    assert!(!dir.path().join("census.h5.partial.d").exists());
}

#[test]
fn sigint_and_sigterm_stop_a_run_after_its_units_in_flight_and_it_resumes() {
    let (_dir, scene, reference, out, journal) = slow_run();
    let (s, o) = (scene.as_str(), out.to_str().unwrap());
    // SIGINT, SIGTERM, and two SIGINTs at once (the second ends the process without
    // waiting); each stop is resumed by the next round, the last one to the end.
    let rounds: [(&[i32], i32, &str); 3] = [
        (&[libc::SIGINT], 130, "SIGINT"),
        (&[libc::SIGTERM], 143, "SIGTERM"),
        (&[libc::SIGINT, libc::SIGINT], 130, "SIGINT"),
    ];
    let mut stopped = 0;
    for (round, (signals, code, name)) in rounds.into_iter().enumerate() {
        let mut args = vec!["run", s, "--out", o, "--quiet"];
        if round > 0 {
            args.push("--resume");
        }
        let mut child = Command::new(BIN)
            .args(&args)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        wait_for_units(&mut child, &journal, unit_files(&journal) + 1);
        for &signal in signals {
            // SAFETY: a signal to our own child process.
            unsafe { libc::kill(child.id() as i32, signal) };
        }
        let output = child.wait_with_output().unwrap();
        let text = String::from_utf8_lossy(&output.stderr);
        if output.status.success() {
            // Finished before the signal landed.
            break;
        }
        stopped += 1;
        assert_eq!(output.status.code(), Some(code), "{name}: {text}");
        if signals.len() == 1 {
            assert!(text.contains(&format!("stopped by {name}")), "{text}");
            assert!(
                text.contains(&format!("rubber-atlas run {s} --out {o} --resume")),
                "{text}"
            );
            assert_eq!(text.lines().count(), 1, "{text}");
        }
        assert!(!out.exists() && journal.exists());
    }
    assert!(stopped >= 2, "the signals landed after the run had ended");
    if !out.exists() {
        ok(&run(&["run", s, "--out", o, "--resume", "--quiet"]));
    }
    assert_same_arrays(&reference, &out);
    assert!(!journal.exists());
}

/// A resumed run that finds a damaged unit in the journal computes it again, says so, and
/// counts it once: the progress never passes the total (it showed 5000/4000 cells).
#[test]
fn a_damaged_journal_unit_is_computed_again_and_counted_once() {
    let (_dir, scene, reference, out, journal) = slow_run();
    let (s, o) = (scene.as_str(), out.to_str().unwrap());
    let mut child = Command::new(BIN)
        .args(["run", s, "--out", o, "--quiet"])
        .spawn()
        .unwrap();
    wait_for_units(&mut child, &journal, 2);
    // SAFETY: a signal to our own child process.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let status = child.wait().unwrap();
    if status.success() {
        return; // finished before the signal landed: nothing to resume
    }
    let unit = std::fs::read_dir(&journal)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "bin"))
        .unwrap();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&unit)
        .unwrap()
        .set_len(10)
        .unwrap();
    let resumed = run(&["run", s, "--out", o, "--resume"]);
    let text = String::from_utf8_lossy(&resumed.stderr);
    assert!(resumed.status.success(), "{text}");
    assert!(text.contains("a damaged unit of the journal"), "{text}");
    for line in text.lines().filter(|l| l.contains(" cells (")) {
        let counts = line.split(": ").nth(1).unwrap().split(' ').next().unwrap();
        let (done, total) = counts.split_once('/').unwrap();
        assert!(
            done.parse::<u64>().unwrap() <= total.parse::<u64>().unwrap(),
            "{line}"
        );
    }
    assert_same_arrays(&reference, &out);
}

/// `args` run to the end, or killed and the test failed where it takes over a minute.
fn run_within_a_minute(args: &[&str]) -> Output {
    let mut child = Command::new(BIN)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("{args:?} still ran after a minute");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Files of a stopped run's journal replaced by what no run writes there (adversary passes 41
/// and 42): a FIFO in a unit's place (opened and waited on for a writer, past SIGTERM, over
/// ten minutes) or an empty folder (every resume failed where the unit was written again) is
/// computed again, and a dangling link at `<out>.partial.h5` (refused in a line of HDF5's
/// internals) replaced; a FIFO or an empty file as the fingerprint is refused in one line
/// saying the journal is damaged. Nothing waits.
#[test]
fn a_journal_with_foreign_files_is_never_waited_on() {
    let (_dir, scene, reference, out, journal) = slow_run();
    let (s, o) = (scene.as_str(), out.to_str().unwrap());
    let fifo_at = |path: &Path| {
        std::fs::remove_file(path).unwrap();
        let made = Command::new("mkfifo").arg(path).status().unwrap();
        assert!(made.success());
    };
    let partial = PathBuf::from(format!("{o}.partial.h5"));
    std::fs::remove_file(&out).ok();
    if stop_a_run(s, &out, &journal, &[]).is_some() {
        let mut units: Vec<PathBuf> = std::fs::read_dir(&journal)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "bin"))
            .collect();
        units.sort();
        fifo_at(&units[0]);
        if let Some(unit) = units.get(1) {
            std::fs::remove_file(unit).unwrap();
            std::fs::create_dir(unit).unwrap();
        }
        std::fs::remove_file(&partial).ok();
        std::os::unix::fs::symlink("/nonexistent/x.h5", &partial).unwrap();
        let resumed = run_within_a_minute(&["run", s, "--out", o, "--resume"]);
        let text = String::from_utf8_lossy(&resumed.stderr);
        assert!(resumed.status.success(), "{text}");
        assert!(text.contains("a damaged unit of the journal"), "{text}");
        assert_same_arrays(&reference, &out);
        std::fs::remove_file(&out).unwrap();
    }
    for fingerprint in ["fifo", "empty"] {
        if stop_a_run(s, &out, &journal, &[]).is_none() {
            continue;
        }
        let path = journal.join("fingerprint");
        if fingerprint == "fifo" {
            fifo_at(&path);
        } else {
            std::fs::write(&path, "").unwrap();
        }
        let refused = run_within_a_minute(&["run", s, "--out", o, "--resume", "--quiet"]);
        let text = String::from_utf8_lossy(&refused.stderr);
        assert!(!refused.status.success(), "{text}");
        assert!(
            text.contains("fingerprint: the journal's fingerprint is damaged")
                && text.contains("--force"),
            "{text}"
        );
        assert_eq!(text.trim().lines().count(), 1, "{text}");
        ok(&run(&["run", s, "--out", o, "--force", "--quiet"]));
        std::fs::remove_file(&out).unwrap();
    }
}

/// A scene of an edged body (docs/bodies.md): `shape` and its axes beside α.
fn edged_scene(dir: &Path, shape: &str, second: &str, plane: &str) -> PathBuf {
    let path = dir.join(format!("{shape}.toml"));
    std::fs::write(
        &path,
        format!(
            "name = \"{shape}\"\n[body]\nshape = \"{shape}\"\nnu = 0.5\neta = 2.0\n[axes]\n\
             alpha = [-0.3, 0.1]\n{second}\n{plane}\n[solver]\ntolerance = 1e-8\n"
        ),
    )
    .unwrap();
    path
}

#[test]
fn edged_body_atlases_equal_the_cell_command_and_their_shards_merge() {
    let dir = tempfile::tempdir().unwrap();
    let plane = "kappa = { start = 0.0, stop = 1.5, num = 12 }\n\
                 energy = { start = 0.5, stop = 3.0, num = 15 }";
    let kappa = |i: usize| axis_value(0.0, 1.5, 12, i);
    let energy = |j: usize| axis_value(0.5, 3.0, 15, j);
    let statuses = [
        "ok",
        "tolerance_not_reached",
        "fixed_point",
        "separatrix",
        "high_energy_limit",
        "reaches_face",
    ];
    let families = ["well_0", "well_pi", "well_equator", "over_the_top"];
    for (shape, second, values) in [
        ("disk", "", &[][..]),
        ("truncated_ball", "cut = [-0.2, 0.4]", &[-0.2, 0.4][..]),
        ("wheel", "cut = [0.3, 0.6]", &[0.3, 0.6][..]),
    ] {
        let scene = edged_scene(dir.path(), shape, second, plane);
        let s = scene.to_str().unwrap();
        let single = dir.path().join(format!("{shape}.h5"));
        let summary = ok(&run(&["run", s, "--out", single.to_str().unwrap()]));
        let file = crate::h5(&single, crate::H5::Read);
        // The dimensions are the shape's parameters: the disk's file has no second one.
        let status = file.dataset("cell_status").unwrap();
        let grid: Vec<usize> = [2].into_iter().chain(values.first().map(|_| 2)).collect();
        assert_eq!(
            status.shape(),
            [grid.clone(), vec![12, 15]].concat(),
            "{shape}"
        );
        assert!(file.dataset("beta").is_err(), "{shape}");
        assert_eq!(file.dataset("cut").is_ok(), !values.is_empty(), "{shape}");
        let attribute = file
            .attr("shape")
            .unwrap()
            .read_scalar::<hdf5::types::VarLenUnicode>();
        assert_eq!(attribute.unwrap().as_str(), shape);
        let read = |name: &str| file.dataset(name).unwrap().read_raw::<f64>().unwrap();
        let flags = |name: &str| file.dataset(name).unwrap().read_raw::<u8>().unwrap();
        let (n, period, theta_min) = (read("rotation_number"), read("period"), read("theta_min"));
        let (count, status, family) = (flags("n_components"), flags("status"), flags("family"));
        let labels = flags("component");
        let slots = labels.len();
        let cuts: Vec<Option<f64>> = if values.is_empty() {
            vec![None]
        } else {
            values.iter().copied().map(Some).collect()
        };
        let mut compared = 0;
        let mut faces = 0;
        for (ia, alpha) in [-0.3, 0.1].into_iter().enumerate() {
            for (ib, cut) in cuts.iter().enumerate() {
                for (ik, ie) in [(0, 4), (0, 12), (3, 7), (6, 14), (11, 13), (9, 2)] {
                    let cell = ((ia * cuts.len() + ib) * 12 + ik) * 15 + ie;
                    let (k, e) = (format!("{:?}", kappa(ik)), format!("{:?}", energy(ie)));
                    let a = alpha.to_string();
                    let mut args = vec![
                        "cell", "--shape", shape, "--alpha", &a, "--nu", "0.5", "--eta", "2",
                        "--kappa", &k, "--energy", &e, "--tol", "1e-8", "--json",
                    ];
                    let c = cut.map(|c| c.to_string());
                    if let Some(c) = &c {
                        args.extend(["--cut", c]);
                    }
                    let json: serde_json::Value = serde_json::from_str(&ok(&run(&args))).unwrap();
                    let components = json["components"].as_array().unwrap();
                    assert_eq!(
                        components.len(),
                        count[cell] as usize,
                        "{shape} cell {cell}"
                    );
                    // Each stored component is one of `cell`'s, bit for bit (null is NaN);
                    // at κ = 0 a family's mirror images share a slot, and one of them is kept.
                    let same = |want: &serde_json::Value, stored: f64| {
                        let want = want.as_f64().unwrap_or(f64::NAN);
                        want.to_bits() == stored.to_bits() || (want.is_nan() && stored.is_nan())
                    };
                    for slot in (0..slots).filter(|&k| family[cell * slots + k] != 255) {
                        let at = cell * slots + slot;
                        let found = components.iter().find(|c| {
                            c["family"] == families[usize::from(labels[slot])]
                                && c["status"] == statuses[usize::from(status[at])]
                                && same(&c["rotation_number"], n[at])
                                && same(&c["period"], period[at])
                                && same(&c["theta_min"], theta_min[at])
                        });
                        assert!(
                            found.is_some(),
                            "{shape} cell {cell} slot {slot}: N {} T {} theta_min {} in the \
                             atlas is none of cell's {components:?}",
                            n[at],
                            period[at],
                            theta_min[at]
                        );
                        faces += usize::from(status[at] == 5);
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared >= 10, "{shape}: {compared} components compared");
        // κ = 0 columns of the disk and the truncated ball reach a face; the summary counts them.
        let line = summary
            .lines()
            .find(|l| l.starts_with("components by status: "))
            .unwrap();
        assert!(line.contains("reaches_face "), "{line}");
        if shape != "wheel" {
            assert!(faces > 0, "{shape}: no component reached a face");
            assert!(!line.ends_with("reaches_face 0"), "{line}");
        }

        // Two shards merged are the single run, bit for bit.
        let shards: Vec<String> = (1..=2)
            .map(|i| {
                let path = dir.path().join(format!("{shape}-{i}.h5"));
                let p = path.to_str().unwrap().to_string();
                ok(&run(&[
                    "run",
                    s,
                    "--out",
                    &p,
                    "--shard",
                    &format!("{i}/2"),
                    "--quiet",
                ]));
                p
            })
            .collect();
        let merged = dir.path().join(format!("{shape}-merged.h5"));
        let m = merged.to_str().unwrap();
        ok(&run(&[
            "merge", &shards[0], &shards[1], "--out", m, "--quiet",
        ]));
        assert_same_arrays(&single, &merged);
    }
}

#[test]
fn edged_body_scenes_are_refused_where_the_shape_does_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let plane = "kappa = [0.5]\nenergy = [1.5]";
    let compact = "lambda = [0.5]\ns = [0.0, 0.5]";
    for (shape, second, plane, extra, expected) in [
        (
            "disk",
            "beta = [2.0]",
            plane,
            "",
            "axes.beta: the shape disk has no parameter beta",
        ),
        (
            "disk",
            "cut = [0.2]",
            plane,
            "",
            "axes.cut: the shape disk has no parameter cut",
        ),
        (
            "wheel",
            "beta = [2.0]",
            plane,
            "",
            "axes.beta: the shape wheel has no parameter beta",
        ),
        ("wheel", "", plane, "", "axes.cut: missing"),
        (
            "wheel",
            "cut = [0.0, 0.5]",
            plane,
            "",
            "axes.cut: 0 must satisfy 0 < cut < 1",
        ),
        (
            "truncated_ball",
            "cut = [1.0]",
            plane,
            "",
            "axes.cut: 1 must satisfy -1 < cut < 1",
        ),
        ("disk", "", plane, "", ""),
        ("disk", "", compact, "", ""),
        ("cube", "", plane, "", "body.shape: unknown shape \"cube\""),
        (
            "truncated_ball",
            "cut = [0.2]",
            plane,
            "method = \"ode\"\n",
            "solver.method: method ode",
        ),
    ] {
        let path = dir.path().join("bad.toml");
        let mut text = edged_scene(dir.path(), shape, second, plane);
        std::fs::write(&path, std::fs::read_to_string(&text).unwrap() + extra).unwrap();
        text = path;
        let out = dir.path().join("bad.h5");
        let output = run(&[
            "run",
            text.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        if expected.is_empty() {
            ok(&output);
            std::fs::remove_file(&out).unwrap();
            continue;
        }
        assert_eq!(output.status.code(), Some(2), "{shape} {second}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(expected), "{shape} {second}: {stderr}");
        assert!(!out.exists());
    }
    // A shard count that does not tile the grid names the shape's own axes.
    for (shape, second, expected) in [
        ("disk", "", "alpha x 1 blocks of kappa rows"),
        ("wheel", "cut = [0.2]", "alpha x 1 cut x 1 blocks"),
    ] {
        let scene = edged_scene(dir.path(), shape, second, plane);
        let out = dir.path().join("shard.h5");
        let output = run(&[
            "run",
            scene.to_str().unwrap(),
            "--shard",
            "1/3",
            "--out",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{shape}: {stderr}");
        assert!(stderr.contains(expected), "{shape}: {stderr}");
        assert!(!stderr.contains("beta"), "{shape}: {stderr}");
    }
}

/// A run of `scene` into `out` with `extra` flags, stopped by SIGINT after its first unit:
/// its stderr, or None if it finished before the signal landed.
fn stop_a_run(scene: &str, out: &Path, journal: &Path, extra: &[&str]) -> Option<String> {
    let mut child = Command::new(BIN)
        .args(["run", scene, "--out", out.to_str().unwrap(), "--quiet"])
        .args(extra)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_units(&mut child, journal, 1);
    // SAFETY: a signal to our own child process.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let output = child.wait_with_output().unwrap();
    (!output.status.success()).then(|| String::from_utf8_lossy(&output.stderr).into_owned())
}

/// A `--force` run of `scene` over `reference` copied to `out`, stopped after its first unit.
fn stop_a_forced_run(scene: &str, reference: &Path, out: &Path, journal: &Path) -> Option<String> {
    std::fs::copy(reference, out).unwrap();
    stop_a_run(scene, out, journal, &["--force"])
}

/// Adversary pass 4: a `--force` run over an existing output, stopped by SIGINT, said
/// "continue with … --resume", and `--resume` then refused because the output existed. It
/// continues the run now, and its output replaces the old one.
#[test]
fn a_forced_run_over_an_output_resumes_as_its_stop_message_says() {
    let (_dir, scene, reference, out, journal) = slow_run();
    let (s, o) = (scene.as_str(), out.to_str().unwrap());
    let Some(text) = stop_a_forced_run(s, &reference, &out, &journal) else {
        return; // finished before the signal landed: nothing to resume
    };
    assert!(
        text.contains(&format!("rubber-atlas run {s} --out {o} --resume")),
        "{text}"
    );
    // The old output is untouched until the run is done.
    assert_eq!(
        std::fs::read(&out).unwrap(),
        std::fs::read(&reference).unwrap()
    );
    ok(&run(&["run", s, "--out", o, "--resume", "--quiet"]));
    assert_same_arrays(&reference, &out);
    assert!(!journal.exists());
}

/// `--resume` replaces only the file the interrupted run was allowed to replace (adversary
/// pass 38: a file put at the output after a run into an empty path had stopped was replaced
/// without a word). A file put there since, or the old output of a stopped `--force` changed
/// since, is refused in one line and kept with the journal; moved away, the run resumes.
#[test]
fn a_resume_replaces_only_the_file_the_stopped_run_was_allowed_to_replace() {
    let (_dir, scene, reference, out, journal) = slow_run();
    let (s, o) = (scene.as_str(), out.to_str().unwrap());
    let refused_resume = |kept: &[u8]| {
        let refused = run(&["run", s, "--out", o, "--resume", "--quiet"]);
        let text = String::from_utf8_lossy(&refused.stderr);
        assert_eq!(refused.status.code(), Some(2), "{text}");
        assert!(
            text.contains("is not what was at this path when the interrupted run started"),
            "{text}"
        );
        assert_eq!(text.trim().lines().count(), 1, "{text}");
        assert_eq!(std::fs::read(&out).unwrap(), kept);
        assert!(journal.exists());
    };
    // A run into an empty path, stopped; then a file of the user's at the path.
    if stop_a_run(s, &out, &journal, &[]).is_some() {
        std::fs::write(&out, "precious\n").unwrap();
        refused_resume(b"precious\n");
        std::fs::remove_file(&out).unwrap();
        ok(&run(&["run", s, "--out", o, "--resume", "--quiet"]));
        assert_same_arrays(&reference, &out);
        assert!(!journal.exists());
    }
    // A stopped `--force` over an output that was written again since.
    if stop_a_forced_run(s, &reference, &out, &journal).is_some() {
        std::thread::sleep(std::time::Duration::from_millis(20));
        let other = std::fs::read(&reference).unwrap();
        std::fs::write(&out, &other).unwrap();
        refused_resume(&other);
    }
}

/// `--update` over a current output that a stopped `--force` run left its journal beside:
/// nothing to do, and the journal (with its partial file) goes, rather than lingering for a
/// later `--resume` to redo the run (adversary pass 4 of issue 22).
#[test]
fn an_update_over_a_current_output_clears_a_stopped_runs_journal() {
    let (_dir, scene, reference, out, journal) = slow_run();
    let (s, o) = (scene.as_str(), out.to_str().unwrap());
    if stop_a_forced_run(s, &reference, &out, &journal).is_none() {
        return; // finished before the signal landed: no journal left
    }
    assert!(journal.exists());
    let done = run(&["run", s, "--out", o, "--update"]);
    ok(&done);
    assert!(String::from_utf8_lossy(&done.stdout).contains("complete and current"));
    assert_eq!(
        std::fs::read(&out).unwrap(),
        std::fs::read(&reference).unwrap()
    );
    assert!(!journal.exists());
    assert!(!Path::new(&format!("{o}.partial.h5")).exists());
}

/// `--update` with another scene at the output where a stopped run left its journal
/// (adversary pass 6: the journal, 20,020 cells, was discarded and the other scene started
/// from nothing): refused in one line, the journal kept for its own run to resume.
#[test]
fn an_update_never_discards_another_scenes_journal() {
    let (dir, scene, _reference, out, journal) = slow_run();
    let o = out.to_str().unwrap();
    std::fs::remove_file(&out).ok();
    if stop_a_run(&scene, &out, &journal, &[]).is_none() {
        return; // finished before the signal landed: no journal left
    }
    let kept = unit_files(&journal);
    let text = std::fs::read_to_string(&scene).unwrap();
    let name_line = text.lines().find(|l| l.starts_with("name")).unwrap();
    let other = dir.path().join("other.toml");
    std::fs::write(&other, text.replace(name_line, "name = \"other\"")).unwrap();
    let refused = run(&["run", other.to_str().unwrap(), "--out", o, "--update"]);
    assert_eq!(
        refused.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&refused.stderr)
    );
    assert!(String::from_utf8_lossy(&refused.stderr).contains("another scene"));
    assert_eq!(unit_files(&journal), kept);
    ok(&run(&["run", &scene, "--out", o, "--resume", "--quiet"]));
}

/// A body of your own (docs/bodies.md): a scene with `shape = "profile"` and the table inline
/// writes an atlas over (α, κ, ε) whose cells are those of `cell --shape profile --profile
/// FILE` bit for bit, with the table in the attribute `profile`; a bad table is refused in
/// one line naming the key.
#[test]
fn a_profile_atlas_equals_the_cell_command() {
    let dir = tempfile::tempdir().unwrap();
    let rows = "[[0.0, -1.0], [0.45, -0.92], [0.8, -0.62], [0.98, -0.2], [0.97, 0.25], \
                [0.8, 0.62, 1], [0.4, 0.8], [0.0, 0.86]]";
    let scene = dir.path().join("egg.toml");
    let write = |profile: &str| {
        std::fs::write(
            &scene,
            format!(
                "name = \"egg\"\n[body]\nshape = \"profile\"\nprofile = {profile}\nnu = 0.8\n\
                 eta = 1.7\n[axes]\nalpha = [-0.1, 0.2]\n\
                 kappa = {{ start = 0.0, stop = 1.5, num = 7 }}\n\
                 energy = {{ start = 0.9, stop = 3.0, num = 9 }}\n[solver]\ntolerance = 1e-10\n"
            ),
        )
        .unwrap()
    };
    write(rows);
    let out = dir.path().join("egg.h5");
    ok(&run(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    let file = crate::h5(&out, crate::H5::Read);
    let text = |name: &str| {
        file.attr(name)
            .unwrap()
            .read_scalar::<hdf5::types::VarLenUnicode>()
            .unwrap()
            .to_string()
    };
    assert_eq!(text("shape"), "profile");
    let table = text("profile");
    assert_eq!(table.lines().count(), 8);
    assert_eq!(table.lines().nth(5), Some("0.8 0.62 1"));
    assert_eq!(file.dataset("cell_status").unwrap().shape(), [2, 7, 9]);
    assert!(file.dataset("beta").is_err() && file.dataset("cut").is_err());
    let flags = |name: &str| file.dataset(name).unwrap().read_raw::<u8>().unwrap();
    let n = file
        .dataset("rotation_number")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    let (count, family) = (flags("n_components"), flags("family"));
    let slots = n.len() / count.len();
    let table_file = dir.path().join("egg.txt");
    std::fs::write(&table_file, &table).unwrap();
    let mut compared = 0;
    for (ia, alpha) in ["-0.1", "0.2"].into_iter().enumerate() {
        for (ik, ie) in [(1, 2), (3, 4), (5, 8), (6, 1)] {
            let cell = (ia * 7 + ik) * 9 + ie;
            let (k, e) = (
                format!("{:?}", axis_value(0.0, 1.5, 7, ik)),
                format!("{:?}", axis_value(0.9, 3.0, 9, ie)),
            );
            let args = [
                "cell",
                "--shape",
                "profile",
                "--profile",
                table_file.to_str().unwrap(),
                "--alpha",
                alpha,
                "--nu",
                "0.8",
                "--eta",
                "1.7",
                "--kappa",
                &k,
                "--energy",
                &e,
                "--json",
            ];
            let json: serde_json::Value = serde_json::from_str(&ok(&run(&args))).unwrap();
            let components = json["components"].as_array().unwrap();
            assert_eq!(components.len(), count[cell] as usize, "cell {cell}");
            for c in components {
                let want = c["rotation_number"].as_f64().unwrap();
                let stored = (0..slots)
                    .filter(|&s| family[cell * slots + s] != 255)
                    .map(|s| n[cell * slots + s]);
                assert!(
                    stored.into_iter().any(|x| x.to_bits() == want.to_bits()),
                    "cell {cell}: N {want} not stored"
                );
                compared += 1;
            }
        }
    }
    assert!(compared >= 6, "{compared}");
    // A table that is no convex meridian: one line, naming the key.
    write("[[0.0, -1.0], [1.0, -0.5], [0.5, 0.0], [1.0, 0.5], [0.0, 1.0]]");
    let refused = run(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
    ]);
    let text = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{text}");
    assert!(
        text.contains("body.profile") && text.contains("not convex"),
        "{text}"
    );
    assert_eq!(text.trim().lines().count(), 1, "{text}");
}

/// Ctrl-C stops a run between two cells, not after its unit: a profile of 2000 points takes
/// about 30 ms a cell, and a unit of 4,096 cells ran on for 111 s after the signal. The unit
/// in flight is dropped (nothing kept), and the journal resumes it.
#[test]
fn a_run_of_slow_cells_stops_between_two_cells() {
    let dir = tempfile::tempdir().unwrap();
    let rows: Vec<String> = (0..2000)
        .map(|i| {
            let t = std::f64::consts::PI * i as f64 / 1999.0;
            let rho = if i == 0 || i == 1999 {
                0.0
            } else {
                1.5 * t.sin()
            };
            format!("[{rho:?}, {:?}]", -t.cos())
        })
        .collect();
    let scene = dir.path().join("slow.toml");
    std::fs::write(
        &scene,
        format!(
            "name = \"slow\"\n[body]\nshape = \"profile\"\nprofile = [{}]\nnu = 1.0\neta = 1.0\n\
             [axes]\nalpha = [0.1]\nkappa = {{ start = 0.05, stop = 1.5, num = 64 }}\n\
             energy = {{ start = 1.6, stop = 4.0, num = 64 }}\n",
            rows.join(", ")
        ),
    )
    .unwrap();
    let out = dir.path().join("slow.h5");
    let (output, heard) = run_interrupted(&scene, &out, Duration::from_millis(1500));
    let text = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{text}");
    // Not a timing test: heard between cells (0.1 s) or after the unit (minutes).
    assert!(heard < Duration::from_secs(20), "{heard:?}: {text}");
    assert!(!out.exists(), "{text}");
}

/// `run scene --out out`, sent SIGINT `after` its start: its output and how long it took to
/// end after the signal.
fn run_interrupted(scene: &Path, out: &Path, after: Duration) -> (Output, Duration) {
    let child = Command::new(BIN)
        .args([
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let sent = Instant::now();
    // SAFETY: a signal to our own child process.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let output = child.wait_with_output().unwrap();
    (output, sent.elapsed())
}

/// Output that does not fit is no bad input: a run, a trajectory and a diagram whose files
/// hit a limit on the way (here a file-size limit, `ulimit -f`, as a full disk would) exit 1
/// with the system's reason in one line; before, a full disk was exit 2, and the atlas's own
/// write said only "H5Dwrite_chunk failed for omega_psi" (adversary pass of 2026-11-27).
#[test]
fn output_that_does_not_fit_is_exit_1_with_the_systems_reason() {
    use std::os::unix::process::CommandExt;
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let limited = |args: &[&str], bytes: u64| {
        let mut command = Command::new(BIN);
        command.args(args);
        // SAFETY: only async-signal-safe calls between fork and exec.
        unsafe {
            command.pre_exec(move || {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let limit = libc::rlimit {
                    rlim_cur: bytes,
                    rlim_max: bytes,
                };
                libc::setrlimit(libc::RLIMIT_FSIZE, &limit);
                Ok(())
            });
        }
        command.output().unwrap()
    };
    let atlas = dir.path().join("a.h5");
    let table = dir.path().join("t.csv");
    let (atlas, table) = (atlas.to_str().unwrap(), table.to_str().unwrap());
    let demo = concat!(env!("CARGO_MANIFEST_DIR"), "/atlas/demo.toml");
    let body = "--alpha 0.5 --beta 3 --nu 0.5 --eta 0.5";
    let cases = [
        // A journal unit does not fit.
        (format!("run {} --out {atlas} --quiet", scene.display()), 20_000),
        // The units fit (13 MB in all, each below 4 MB) and the atlas does not: HDF5's write.
        (format!("run {demo} --out {atlas} --quiet --force"), 4_000_000),
        (
            format!("trajectory {body} --kappa 0.8 --energy 2.5 --periods 3 --samples 100000 --out {table}"),
            20_000,
        ),
        (format!("diagram {body} --samples 100000 --out {table}"), 20_000),
    ];
    for (line, bytes) in cases {
        let args: Vec<&str> = line.split_whitespace().collect();
        let o = limited(&args, bytes);
        let text = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {text}");
        assert!(
            text.contains("File too large") && text.lines().count() == 1,
            "{args:?}: {text}"
        );
    }
}

/// The census of a grid of 1e12 bodies stops at once when asked: its pass over the bodies and
/// its iteration over their κ-rows both end at the first `stop` (each went on over every
/// remaining body, minutes after a SIGINT at 1e6 × 1e6; an adversary pass). Counted, not
/// timed: `stop` is asked a handful of times, not once a body.
#[test]
fn the_census_of_a_huge_grid_stops_when_asked() {
    let scene = rubber_atlas::scene::Scene::parse(
        "name = \"huge\"\n[body]\nnu = 0.5\neta = 0.5\n[axes]\n\
         alpha = { start = -0.9, stop = 0.9, num = 1000000 }\n\
         beta = { start = 0.1, stop = 10.0, num = 1000000 }\nkappa = [1.0]\nenergy = [2.0]\n",
        "huge.toml",
    )
    .unwrap();
    let asked = std::sync::atomic::AtomicUsize::new(0);
    let stop = || asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 100;
    rubber_atlas::atlas::census(&scene, &stop);
    let asked = asked.into_inner();
    assert!(asked <= 1000, "stop asked {asked} times");
}

/// A scene `name` of one ellipsoid and `n` × `n` cells, and a fresh run of it into
/// `dir/<name>.h5`, for runs in this process (through the library, with a progress of the
/// test's own).
fn in_process_run(
    dir: &Path,
    name: &str,
    n: usize,
) -> (rubber_atlas::scene::Scene, rubber_atlas::sweep::RunRequest) {
    let scene = rubber_atlas::scene::Scene::parse(
        &format!(
            "name = \"{name}\"\n[body]\nnu = 0.5\neta = 0.5\n[axes]\nalpha = [0.5]\n\
             beta = [3.0]\nkappa = {{ start = 0.05, stop = 2.0, num = {n} }}\n\
             energy = {{ start = 0.5, stop = 4.5, num = {n} }}\n"
        ),
        &format!("{name}.toml"),
    )
    .unwrap();
    let request = rubber_atlas::sweep::RunRequest {
        out: dir.join(format!("{name}.h5")),
        resume: false,
        force: false,
        update: false,
        output_current: false,
        shard: rubber_atlas::atlas::Shard::WHOLE,
        attributes: Vec::new(),
    };
    (scene, request)
}

/// A run stopped part way takes back the cells of the units it drops: what the progress
/// says is done is what the journal keeps (after Ctrl-C the progress line had counted the
/// dropped unit's cells as done; an adversary pass).
#[test]
fn a_stopped_run_counts_only_the_cells_it_keeps() {
    use rubber_atlas::sweep::Progress;
    use std::sync::atomic::{AtomicU64, Ordering};
    struct Counting {
        done: AtomicU64,
        stop_after: u64,
    }
    impl Progress for Counting {
        fn begin(&self, _total: u64, done: u64) {
            self.done.store(done, Ordering::SeqCst);
        }
        fn advance(&self, cells: u64) {
            self.done.fetch_add(cells, Ordering::SeqCst);
        }
        fn retract(&self, cells: u64) {
            self.done.fetch_sub(cells, Ordering::SeqCst);
        }
        fn dropped(&self, cells: u64) {
            self.done.fetch_sub(cells, Ordering::SeqCst);
        }
        fn interrupted(&self) -> bool {
            self.done.load(Ordering::SeqCst) >= self.stop_after
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, request) = in_process_run(dir.path(), "stopped", 64);
    // Stopped after a row and a half of 64 cells: the unit in flight is dropped part way.
    let progress = Counting {
        done: AtomicU64::new(0),
        stop_after: 96,
    };
    let err = rubber_atlas::sweep::run(&scene, &request, &progress).unwrap_err();
    let rubber_atlas::AtlasError::Interrupted { done, total, .. } = err else {
        panic!("{err}");
    };
    assert_eq!(total, 64 * 64);
    assert!(done < total);
    assert_eq!(progress.done.into_inner(), done);
}

/// Adversary pass of 2026-11-28: a run's lock file removed while it wrote (by hand, or by a
/// clean-up script after a preemption) let a second `run --force` claim the output, remove
/// the first's partial file and write its own; the first then renamed the second's
/// half-written file into place and exited 0. A claim now knows when its lock file is no
/// longer the one at the path: the finished file is not put in place (exit 75), and its
/// drop leaves the second's lock file alone.
#[test]
fn a_claim_whose_lock_file_was_removed_publishes_nothing() {
    use rubber_atlas::store::OutputLock;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.h5");
    let lock = dir.path().join("o.h5.lock");
    let first = OutputLock::acquire(&out).unwrap();
    assert!(first.is_held());
    assert!(
        OutputLock::acquire(&out).is_err(),
        "a second claim while held"
    );
    std::fs::remove_file(&lock).unwrap();
    assert!(!first.is_held());
    let second = OutputLock::acquire(&out).unwrap();
    let refused = first.check_held(&out).unwrap_err();
    assert!(
        matches!(refused, rubber_atlas::AtlasError::Busy { .. }),
        "{refused}"
    );
    assert!(refused.to_string().contains("not replaced"), "{refused}");
    drop(first);
    assert!(
        lock.exists() && second.is_held(),
        "the second's lock file kept"
    );
    drop(second);
    assert!(!lock.exists());
}

/// A journal removed while the run writes it is a failed run: exit 1 (not 2, which says the
/// input was bad), one line naming the journal, and no output nor partial file left behind.
#[test]
fn a_journal_removed_mid_run_fails_the_run_with_exit_1() {
    let (_dir, scene, _reference, out, journal) = slow_run();
    let mut child = Command::new(BIN)
        .args(["run", &scene, "--out", out.to_str().unwrap(), "--quiet"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_units(&mut child, &journal, 1);
    std::fs::remove_dir_all(&journal).unwrap();
    let output = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(text.contains("o.h5.partial.d"), "{text}");
    assert!(!out.exists(), "{text}");
    let left = files_named(out.parent().unwrap(), "o.h5");
    assert!(left.is_empty(), "{left:?}");
}

/// A signal while the finished file is written stops the run as at any other moment: the
/// file is not put in place, the journal keeps every unit, and a resumed run writes it
/// without computing a cell (the run used to finish and exit 0 after Ctrl-C there).
#[test]
fn a_run_asked_to_stop_while_it_writes_the_file_keeps_every_unit_for_resume() {
    use rubber_atlas::sweep::{Progress, Silent};
    use std::sync::atomic::{AtomicBool, Ordering};
    #[derive(Default)]
    struct StopWhileWriting(AtomicBool);
    impl Progress for StopWhileWriting {
        fn writing(&self) {
            self.0.store(true, Ordering::SeqCst);
        }
        fn interrupted(&self) -> bool {
            self.0.load(Ordering::SeqCst)
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, mut request) = in_process_run(dir.path(), "w", 16);
    let err = rubber_atlas::sweep::run(&scene, &request, &StopWhileWriting::default()).unwrap_err();
    let rubber_atlas::AtlasError::Interrupted { done, total, .. } = err else {
        panic!("{err}");
    };
    assert_eq!((done, total), (256, 256));
    assert!(!request.out.exists());
    assert!(dir.path().join("w.h5.partial.d").exists());
    request.resume = true;
    let summary = rubber_atlas::sweep::run(&scene, &request, &Silent).unwrap();
    assert_eq!(summary.cells_computed, 0, "{summary:?}");
    assert!(request.out.exists() && !dir.path().join("w.h5.partial.d").exists());
}

/// A run whose progress and summary go into a closed pipe (`run … 2>&1 | head -c 10`) ends
/// as it would have, with its file in place: it was killed by SIGPIPE at its first progress
/// line, leaving its lock and an empty journal that blocked the next run.
#[test]
fn a_run_into_a_closed_pipe_finishes_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let out = dir.path().join("piped.h5");
    let mut child = Command::new(BIN)
        .args([
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Both pipes' reading ends closed before the run writes a line.
    drop(child.stdout.take());
    drop(child.stderr.take());
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    assert!(out.exists());
    assert_eq!(files_named(dir.path(), "piped.h5"), ["piped.h5"]);
}

/// A shard whose HDF5 metadata is damaged so that reading it crashes HDF5 (a length in its
/// global heap: a flipped bit) is refused in one line, exit 2, naming it, with no lock or
/// partial file left: `merge` died of a segmentation fault there (an adversary pass). The
/// shards are read first in a child process; the test flips bits until one crashes it.
#[test]
fn a_shard_that_crashes_hdf5_is_refused_by_merge() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let s = scene.to_str().unwrap();
    let shard = |i: usize| dir.path().join(format!("small.shard-{i}-of-2.h5"));
    for i in 1..=2 {
        let out = shard(i);
        let n = format!("{i}/2");
        ok(&run(&[
            "run",
            s,
            "--shard",
            &n,
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]));
    }
    let good = std::fs::read(shard(2)).unwrap();
    let bad = dir.path().join("bad.h5");
    let out = dir.path().join("merged.h5");
    let merge = |extra: &[&str]| {
        let mut args: Vec<String> = vec![
            "merge".into(),
            shard(1).to_str().unwrap().to_owned(),
            bad.to_str().unwrap().to_owned(),
            "--out".into(),
            out.to_str().unwrap().to_owned(),
        ];
        args.extend(extra.iter().map(|a| a.to_string()));
        Command::new(BIN).args(&args).output().unwrap()
    };
    let crashing = (1500..6000).find(|&offset| {
        let mut bytes = good.clone();
        bytes[offset] ^= 1;
        std::fs::write(&bad, &bytes).unwrap();
        merge(&["--probe-shards"]).status.signal() == Some(libc::SIGSEGV)
    });
    let offset = crashing.expect("some flipped bit crashes HDF5's reading of the shard");
    let output = merge(&[]);
    let text = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "offset {offset}: {text}");
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(
        text.contains("bad.h5") && text.contains("damaged"),
        "{text}"
    );
    assert!(files_named(dir.path(), "merged.h5").is_empty());
}

/// Without a terminal the progress comes as lines; the last tally (every cell done) comes
/// before "writing the file", which is the last line (it came after it: an adversary pass).
#[test]
fn progress_lines_end_with_the_tally_and_then_the_writing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let out = dir.path().join("o.h5");
    let output = run(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    ok(&output);
    let text = String::from_utf8_lossy(&output.stderr).into_owned();
    let lines: Vec<&str> = text.lines().collect();
    let n = lines.len();
    assert!(n >= 2, "{text}");
    assert_eq!(lines[n - 1], "run small: writing the file", "{text}");
    assert!(
        lines[n - 2].starts_with("run small: 3840/3840 cells (100.0%)"),
        "{text}"
    );
}

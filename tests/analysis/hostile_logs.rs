//! Logs as a careless user, a malicious file or a busy lab hands them over: too many stimuli for
//! memory, a device, the same log twice, random answers. Each is refused with a figure or reported
//! for what it is, never a crash and never a made-up number.

use std::fmt::Write;
use std::path::Path;
use std::process::{Command, Output};

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::{analyze, json_of};

/// An address-space limit under which the analyses must run their inputs or refuse them.
const MEMORY_LIMIT_BYTES: u64 = 4 << 30;

/// `sake-glug analyze ARGS` in `directory`, its address space limited to
/// [`MEMORY_LIMIT_BYTES`]: an allocation past it aborts the process, as on a small machine.
fn analyze_limited(directory: &Path, args: &[&str]) -> Output {
    use std::os::unix::process::CommandExt;
    let mut command = Command::new(env!("CARGO_BIN_EXE_sake-glug"));
    command.current_dir(directory).arg("analyze").args(args);
    // SAFETY: only setrlimit, async-signal-safe, runs between fork and exec.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: MEMORY_LIMIT_BYTES,
                rlim_max: MEMORY_LIMIT_BYTES,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    command.output().unwrap()
}

fn refused_with(output: &Output, code: i32, parts: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(
        output.status.code(),
        Some(code),
        "{:?}: {stderr}",
        output.status
    );
    assert!(output.stdout.is_empty(), "no result printed");
    for part in parts {
        assert!(stderr.contains(part), "no `{part}` in: {stderr}");
    }
    stderr
}

/// A 1 MB log naming 40,000 stimuli asked for matrices of 40,000² cells (45 GB), which aborted
/// under 4 GB: the count is bounded and the rest refused with the figure.
#[test]
fn a_log_naming_forty_thousand_stimuli_is_refused_with_the_figure() {
    let folder = tempfile::tempdir().unwrap();
    let mut log = String::from("participant,first,second,answer\n");
    for index in 0..40_000 {
        writeln!(log, "p,s{index},s{},s{index}", index + 1).unwrap();
    }
    assert!(log.len() > 700_000, "{} bytes", log.len());
    std::fs::write(folder.path().join("log.csv"), log).unwrap();
    let output = analyze_limited(folder.path(), &["paired", "log.csv"]);
    refused_with(&output, 1, &["log.csv", "more than 256 stimuli"]);
}

/// Fewer trials than pairs: some pair is never compared, said before the matrices are made.
#[test]
fn more_pairs_than_trials_are_refused_before_counting() {
    let folder = tempfile::tempdir().unwrap();
    let mut log = String::from("participant,first,second,answer\n");
    for index in 0..100 {
        writeln!(log, "p,s{index},s{},s{index}", index + 1).unwrap();
    }
    std::fs::write(folder.path().join("log.csv"), log).unwrap();
    let output = analyze_limited(folder.path(), &["paired", "log.csv"]);
    refused_with(&output, 1, &["101 stimuli make 5050 pairs", "100 trials"]);
}

#[test]
fn a_device_is_refused_at_once() {
    let folder = tempfile::tempdir().unwrap();
    for design in ["paired", "constant"] {
        let output = analyze_limited(folder.path(), &[design, "/dev/zero"]);
        refused_with(&output, 1, &["/dev/zero", "not a regular file"]);
    }
}

const PAIRED: &str = "participant,trial,first,second,answer\n\
    P01,1,a,b,a\nP01,2,b,c,b\nP01,3,c,a,a\n";

/// `analyze paired P01.csv ./P01.csv P05.csv` counted P01 twice; so did a copy of it.
#[test]
fn a_log_given_twice_is_refused_with_both_names() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(folder.path().join("P01.csv"), PAIRED).unwrap();
    std::fs::write(folder.path().join("P05.csv"), PAIRED.replace("P01", "P05")).unwrap();
    let output = analyze(
        folder.path(),
        &["paired", "P01.csv", "./P01.csv", "P05.csv"],
    );
    refused_with(&output, 1, &["./P01.csv: the same file as P01.csv"]);
    std::fs::hard_link(
        folder.path().join("P01.csv"),
        folder.path().join("link.csv"),
    )
    .unwrap();
    let output = analyze(folder.path(), &["paired", "P01.csv", "link.csv"]);
    refused_with(&output, 1, &["link.csv: the same file as P01.csv"]);
    // A copy is another file, but the same participant's same trials.
    std::fs::copy(
        folder.path().join("P01.csv"),
        folder.path().join("copy.csv"),
    )
    .unwrap();
    let output = analyze(folder.path(), &["paired", "P01.csv", "copy.csv", "P05.csv"]);
    refused_with(
        &output,
        1,
        &[
            "copy.csv, line 2",
            "participant `P01`, trial `1` again",
            "P01.csv, line 2",
        ],
    );
    // Within one log too; and the logs as they are analyse.
    let twice = format!("{PAIRED}P01,2,a,c,a\n");
    std::fs::write(folder.path().join("twice.csv"), twice).unwrap();
    let output = analyze(folder.path(), &["paired", "twice.csv"]);
    refused_with(&output, 1, &["twice.csv, line 5", "trial `2` again"]);
    let json = json_of(&analyze(
        folder.path(),
        &["paired", "P01.csv", "P05.csv", "--json"],
    ));
    assert_eq!(json["trials"], 6);
}

/// The paper's nine levels, ten trials each, for three participants who answer at random.
fn random_answers(seed: u64) -> String {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut log = String::from("participant,trial,level,chose_comparison\n");
    for participant in 0..3 {
        let mut trial = 0;
        for level in [0.18, 0.22, 0.26, 0.29, 0.33, 0.37, 0.41, 0.45, 0.49] {
            for _ in 0..10 {
                trial += 1;
                let chosen = u8::from(rng.random::<bool>());
                writeln!(log, "p{participant},{trial},{level},{chosen}").unwrap();
            }
        }
    }
    log
}

/// Random answers gave "25 %: 4.4699 95 % [3.0048, 15300842255015416]" for levels 0.18–0.49,
/// and a 75 % point below the 25 %. Whatever the answers, a number reported is within the levels
/// tested, with its interval's ends within them or `null`, the points in order; or the curve is
/// refused as not rising.
#[test]
fn random_answers_give_no_number_outside_the_levels_tested() {
    let (lowest, highest) = (0.18, 0.49);
    let mut outside = 0;
    let mut falling = 0;
    for seed in 0..20 {
        let folder = tempfile::tempdir().unwrap();
        std::fs::write(folder.path().join("log.csv"), random_answers(seed)).unwrap();
        let output = analyze(
            folder.path(),
            &["constant", "log.csv", "--json", "--resamples", "200"],
        );
        if output.status.code() == Some(1) {
            refused_with(&output, 1, &["does not rise"]);
            falling += 1;
            continue;
        }
        let json = json_of(&output);
        let fits = std::iter::once(&json).chain(
            json["participants"]
                .as_object()
                .unwrap()
                .values()
                .filter(|fit| fit.get("points").is_some()),
        );
        for fit in fits {
            let mut previous = f64::NEG_INFINITY;
            for percent in ["25", "50", "75"] {
                let point = &fit["points"][percent];
                let Some(value) = point["value"].as_f64() else {
                    assert!(point["low"].is_null() && point["high"].is_null(), "{point}");
                    assert_ne!(point["placement"], "within", "{point}");
                    outside += 1;
                    continue;
                };
                assert_eq!(point["placement"], "within", "{point}");
                assert!((lowest..=highest).contains(&value), "seed {seed}: {point}");
                assert!(value >= previous, "seed {seed}: {fit}");
                previous = value;
                for end in ["low", "high"] {
                    if let Some(level) = point[end].as_f64() {
                        assert!((lowest..=highest).contains(&level), "seed {seed}: {point}");
                    }
                }
            }
        }
    }
    assert!(
        outside > 0,
        "random answers put some point outside the levels"
    );
    assert!(falling > 0, "random answers make some curve fall");
}

/// Answers that fall with the level: the curve does not rise, and no point is reported.
#[test]
fn a_falling_curve_is_refused_as_such() {
    let folder = tempfile::tempdir().unwrap();
    let mut log = String::from("participant,level,chose_comparison\n");
    for (level, chosen) in [(0.2, 8), (0.3, 6), (0.4, 4), (0.5, 2)] {
        for trial in 0..10 {
            writeln!(log, "p,{level},{}", u8::from(trial < chosen)).unwrap();
        }
    }
    std::fs::write(folder.path().join("log.csv"), log).unwrap();
    let output = analyze(folder.path(), &["constant", "log.csv", "--resamples", "50"]);
    refused_with(
        &output,
        1,
        &["all participants", "does not rise", "slope -"],
    );
}

#[test]
fn too_many_resamples_are_refused_with_the_limit() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(folder.path().join("log.csv"), random_answers(1)).unwrap();
    for count in ["18446744073709551615", "100001", "0"] {
        let output = analyze(
            folder.path(),
            &["constant", "log.csv", "--resamples", count],
        );
        refused_with(&output, 2, &["--resamples", "1..=100000"]);
    }
}

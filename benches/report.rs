//! A benchmark's report, written with the commit and the processor it measured to
//! `<target>/bench-<name>.md`, which `cargo xtask docs` copies into the docs: one writer for every
//! benchmark that reports.

use std::process::Command;

/// Writes `lines`, the report of the benchmark `name` (`cargo bench --bench capi` reports as
/// "capi"), to `<target>/bench-<name>.md` (the target directory is found from this executable's
/// path, `<target>/release/deps/<name>-…`).
pub fn save(name: &str, lines: &str) {
    let Some(target) = std::env::current_exe()
        .ok()
        .and_then(|exe| Some(exe.parent()?.parent()?.parent()?.to_owned()))
    else {
        return;
    };
    let commit = Command::new("git")
        .args(["describe", "--always", "--dirty"])
        .output()
        .ok()
        .filter(|out| out.status.success())
        .map_or("unknown".into(), |out| {
            String::from_utf8_lossy(&out.stdout).trim().to_owned()
        });
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|line| line.starts_with("model name"))
                .and_then(|line| line.split(':').nth(1))
                .map(|name| name.trim().to_owned())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let text = format!(
        "`cargo bench --bench {name}` at commit {commit}, one core of {cpu}:\n\n```\n{lines}```\n"
    );
    let path = target.join(format!("bench-{name}.md"));
    match std::fs::write(&path, text) {
        Ok(()) => println!("written to {}", path.display()),
        Err(error) => println!("cannot write {}: {error}", path.display()),
    }
}

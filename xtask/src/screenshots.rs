//! `cargo xtask screenshots`: the editor in a real window, photographed by code.
//!
//! The release standalone app runs under a virtual X server (Xvfb) on nice-plug's dummy audio
//! backend, which still calls the plugin's `process()` every period (256 frames at 48 kHz) but
//! needs no sound card or JACK server. Its window is found with xdotool and captured with
//! ImageMagick's `import`: `docs/editor-idle.png` once the upright bottle's editor has painted
//! and settled, then `docs/editor-pouring.png` once a phone's gravity vector, sent over OSC on
//! loopback, has tilted the bottle to 135° and the scope shows the glugs. It also measures the
//! app's CPU time over 10 s idle and 10 s pouring (printed by thread; nothing is asserted on it),
//! and returns a sentence on it for the guide (docs/guide/sound-designer.md).
//!
//! Every process started here is stopped when this returns, also on error.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};

/// The programs this needs, and the Debian package of each.
const TOOLS: [(&str, &str); 3] = [
    ("Xvfb", "xvfb"),
    ("xdotool", "xdotool"),
    ("import", "imagemagick"),
];

/// The editor window's title (`EguiNiceSettings::with_tile` in crates/plugin/src/editor/mod.rs).
const WINDOW_TITLE: &str = "^Sake Glug$";

/// The tilt of the pouring shot, in degrees: where MODEL.md's pour time is defined.
const POUR_TILT_DEG: f32 = 135.0;

/// How long after the tilt the pouring shot is taken at the earliest: the first glug comes
/// about 90 ms after it, so by then the scope's 0.6 s shows several.
const POUR_SHOT_AFTER: Duration = Duration::from_millis(800);

/// The scope's trace colour (crates/plugin/src/editor/scope.rs) and how far a pixel may be from it
/// (anti-aliasing) to count as trace.
const TRACE_RGB: [u8; 3] = [120, 200, 255];
const TRACE_TOLERANCE: u8 = 40;

/// How many trace pixels make "the scope shows glugs": one glug is a burst of full-height
/// columns, thousands of pixels; the idle scope has none.
const TRACE_PIXELS_MIN: usize = 500;

/// Fewer colours than this is a window not painted yet (a cleared window has one or two).
const PAINTED_COLOURS_MIN: usize = 16;

/// The OSC port the app listens on when it is free, so that the shots show the same number on
/// every run.
const SHOWN_OSC_PORT: u16 = 9000;

/// How long each CPU measurement lasts.
const CPU_WINDOW: Duration = Duration::from_secs(10);

/// How often the bottle is refilled while the pouring CPU time is measured: a full bottle at
/// 135° glugs for about 4 s, so it never runs dry.
const REFILL_EVERY: Duration = Duration::from_secs(2);

/// How long the app and the X server get to start, paint, or stop.
const START_TIMEOUT: Duration = Duration::from_secs(60);
const STOP_TIMEOUT: Duration = Duration::from_secs(10);

/// Fails, naming each program and its Debian package, if a tool this needs is not installed
/// (checked before the app is built, so a missing tool is said at once).
pub fn check_tools() -> anyhow::Result<()> {
    let missing: Vec<String> = TOOLS
        .iter()
        .filter(|(program, _)| !on_path(program))
        .map(|(program, package)| format!("{program} (Debian: {package})"))
        .collect();
    if !missing.is_empty() {
        bail!(
            "cargo xtask screenshots needs {}: not found on PATH",
            missing.join(", ")
        );
    }
    Ok(())
}

/// Runs the app under Xvfb, writes docs/editor-idle.png and docs/editor-pouring.png, prints the
/// app's CPU time idle and pouring by thread, and returns a sentence on it. `app` is the release
/// standalone app, already built; `work` holds the raw shots and the logs.
pub fn screenshots(app: &Path, work: &Path) -> anyhow::Result<String> {
    if !app.exists() {
        bail!(
            "{} is missing: the standalone build did not make it",
            app.display()
        );
    }
    std::fs::create_dir_all(work)?;

    let xvfb = Xvfb::start(&work.join("xvfb.log"))?;
    println!("screenshots: Xvfb on {}", xvfb.display);
    let osc_port = osc_port()?;
    let app_log = work.join("app.log");
    let mut app = Stopped::spawn(
        "the standalone app",
        Command::new(app)
            .args(["--backend", "dummy", "--sample-rate", "48000"])
            .args(["--period-size", "256", "--osc-port", &osc_port.to_string()])
            .args(["--osc-axis", "+y"])
            .env("DISPLAY", &xvfb.display)
            .stdin(Stdio::null())
            .stdout(File::create(&app_log)?)
            .stderr(File::create(app_log.with_extension("stderr.log"))?),
    )?;
    let logs = [app_log.clone(), app_log.with_extension("stderr.log")];
    let window = wait_for(START_TIMEOUT, "the editor window", || {
        app.check_running(&logs)?;
        find_window(&xvfb.display)
    })?;
    wait_for(START_TIMEOUT, "the app to listen for OSC", || {
        app.check_running(&logs)?;
        Ok(logs
            .iter()
            .any(|log| read_lossy(log).contains("OSC: listening"))
            .then_some(()))
    })?;
    // The pointer off the window, so that no widget is drawn hovered.
    x_command(&xvfb.display, "xdotool", &["mousemove", "1020", "764"])?;

    // Idle: painted, and the same picture twice in a row (nothing left to draw).
    let shot = |name: &str| -> anyhow::Result<Picture> {
        let file = work.join(name);
        x_command(
            &xvfb.display,
            "import",
            &[
                "-window",
                &window,
                // No time stamps in the file: the same picture gives the same bytes.
                "-define",
                "png:exclude-chunks=date,time",
                &file.to_string_lossy(),
            ],
        )?;
        Picture::read(&file)
    };
    let mut previous: Option<Picture> = None;
    let idle = wait_for(START_TIMEOUT, "the editor to paint and settle", || {
        app.check_running(&logs)?;
        let picture = shot("idle.png")?;
        let settled = picture.colours() >= PAINTED_COLOURS_MIN
            && previous
                .as_ref()
                .is_some_and(|last| last.pixels == picture.pixels);
        if settled {
            return Ok(Some(picture));
        }
        previous = Some(picture);
        std::thread::sleep(Duration::from_millis(300));
        Ok(None)
    })?;
    if idle.trace_pixels() >= TRACE_PIXELS_MIN {
        bail!(
            "the idle editor already shows {} scope trace pixels: the upright bottle should be \
             silent",
            idle.trace_pixels()
        );
    }
    publish(&idle.file, "docs/editor-idle.png")?;

    let idle_cpu = cpu_over(app.pid(), CPU_WINDOW, || Ok(()))?;

    // Pouring: a phone held along the bottle (+y to the mouth) sends its gravity vector.
    let sender = UdpSocket::bind(("127.0.0.1", 0))?;
    let send = |message: rosc::OscMessage| -> anyhow::Result<()> {
        let bytes = rosc::encoder::encode(&rosc::OscPacket::Message(message))?;
        sender.send_to(&bytes, ("127.0.0.1", osc_port))?;
        Ok(())
    };
    let tilt = || send(gravity_message(POUR_TILT_DEG));
    let refill = || {
        send(rosc::OscMessage {
            addr: "/sakeglug/refill".into(),
            args: vec![],
        })
    };
    tilt()?;
    let tilted = Instant::now();
    let pouring = wait_for(START_TIMEOUT, "the scope to show the glugs", || {
        app.check_running(&logs)?;
        let wait = POUR_SHOT_AFTER.saturating_sub(tilted.elapsed());
        std::thread::sleep(wait);
        let picture = shot("pouring.png")?;
        Ok((picture.trace_pixels() >= TRACE_PIXELS_MIN).then_some(picture))
    })?;
    let shot_after = tilted.elapsed();
    publish(&pouring.file, "docs/editor-pouring.png")?;

    refill()?;
    let mut last_refill = Instant::now();
    let pouring_cpu = cpu_over(app.pid(), CPU_WINDOW, || {
        if last_refill.elapsed() >= REFILL_EVERY {
            refill()?;
            last_refill = Instant::now();
        }
        Ok(())
    })?;

    app.stop()?;
    drop(xvfb);
    println!(
        "screenshots: docs/editor-pouring.png {:.2} s after the tilt, {} scope trace pixels",
        shot_after.as_secs_f64(),
        pouring.trace_pixels()
    );
    println!(
        "CPU time of the app over {} s, in all and by thread (the unnamed ones are the wrapper's \
         audio loop and the editor's window; llvmpipe-* draw it, as Xvfb has no GPU):",
        CPU_WINDOW.as_secs()
    );
    println!("  idle, upright: {idle_cpu}");
    println!("  pouring:       {pouring_cpu}");
    let window_s = CPU_WINDOW.as_secs();
    Ok(format!(
        "the app used {:.2} s of CPU in {window_s} s upright and idle, {:.2} s in {window_s} s \
         of pouring (refilled every {} s; {:.2} s of it in Mesa's software OpenGL threads)",
        idle_cpu.total_s,
        pouring_cpu.total_s,
        REFILL_EVERY.as_secs(),
        pouring_cpu.software_gl_s()
    ))
}

/// Whether `program` is an executable file in one of PATH's directories.
fn on_path(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|path| {
        std::env::split_paths(&path).any(|dir| {
            std::fs::metadata(dir.join(program)).is_ok_and(|meta| {
                meta.is_file()
                    && std::os::unix::fs::PermissionsExt::mode(&meta.permissions()) & 0o111 != 0
            })
        })
    })
}

/// The port the editor's OSC panel shows: [`SHOWN_OSC_PORT`] when it is free (the app binds
/// it a moment later, on every interface), else any free one.
fn osc_port() -> anyhow::Result<u16> {
    if UdpSocket::bind(("0.0.0.0", SHOWN_OSC_PORT)).is_ok() {
        return Ok(SHOWN_OSC_PORT);
    }
    Ok(UdpSocket::bind(("0.0.0.0", 0))?.local_addr()?.port())
}

/// GyrOSC's `/gyrosc/grav x y z` for a phone whose +y axis points from the bottle's base to its
/// mouth, the bottle tilted `tilt_deg` from upright in the phone's y–z plane. GyrOSC reports
/// gravity pointing to the earth (crates/device/src/osc.rs), so upright reads (0, −1, 0).
fn gravity_message(tilt_deg: f32) -> rosc::OscMessage {
    let (sin, cos) = tilt_deg.to_radians().sin_cos();
    rosc::OscMessage {
        addr: "/gyrosc/grav".into(),
        args: [0.0, -cos, -sin]
            .into_iter()
            .map(rosc::OscType::Float)
            .collect(),
    }
}

/// Calls `poll` until it gives a value or `timeout` has passed (then fails naming `what`).
fn wait_for<T>(
    timeout: Duration,
    what: &str,
    mut poll: impl FnMut() -> anyhow::Result<Option<T>>,
) -> anyhow::Result<T> {
    let started = Instant::now();
    loop {
        if let Some(value) = poll()? {
            return Ok(value);
        }
        if started.elapsed() > timeout {
            bail!("timed out after {} s waiting for {what}", timeout.as_secs());
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The editor's window id, once it exists.
fn find_window(display: &str) -> anyhow::Result<Option<String>> {
    let out = Command::new("xdotool")
        .args(["search", "--name", WINDOW_TITLE])
        .env("DISPLAY", display)
        .output()
        .context("running xdotool")?;
    // xdotool exits with 1 when nothing matches yet.
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .next()
        .map(str::to_owned))
}

/// Runs an X client on `display`; fails with its error output.
fn x_command(display: &str, program: &str, args: &[&str]) -> anyhow::Result<()> {
    let out = Command::new(program)
        .args(args)
        .env("DISPLAY", display)
        .output()
        .with_context(|| format!("running {program}"))?;
    if !out.status.success() {
        bail!(
            "`{program} {}` failed ({}): {}",
            args.join(" "),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    Ok(())
}

/// Copies a shot into docs/ through a temporary file, so a failed copy leaves the old picture.
fn publish(shot: &Path, target: &str) -> anyhow::Result<()> {
    let temporary = PathBuf::from(format!("{target}.tmp"));
    std::fs::copy(shot, &temporary)?;
    std::fs::rename(&temporary, target)?;
    println!("{target} written");
    Ok(())
}

fn read_lossy(path: &Path) -> String {
    std::fs::read(path)
        .map(|bytes| String::from_utf8_lossy(&bytes).into_owned())
        .unwrap_or_default()
}

/// A screenshot's pixels, as RGB.
struct Picture {
    file: PathBuf,
    pixels: Vec<[u8; 3]>,
}

impl Picture {
    fn read(file: &Path) -> anyhow::Result<Self> {
        let mut decoder = png::Decoder::new(
            File::open(file).with_context(|| format!("opening {}", file.display()))?,
        );
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder
            .read_info()
            .with_context(|| format!("reading {}", file.display()))?;
        let mut buffer = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buffer)?;
        let bytes = &buffer[..info.buffer_size()];
        let pixels = match info.color_type {
            png::ColorType::Rgb => bytes.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
            png::ColorType::Rgba => bytes.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect(),
            png::ColorType::Grayscale => bytes.iter().map(|&g| [g; 3]).collect(),
            png::ColorType::GrayscaleAlpha => bytes.chunks_exact(2).map(|p| [p[0]; 3]).collect(),
            png::ColorType::Indexed => bail!("{}: palette left unexpanded", file.display()),
        };
        Ok(Self {
            file: file.to_owned(),
            pixels,
        })
    }

    /// How many different colours the picture has.
    fn colours(&self) -> usize {
        let mut seen: Vec<[u8; 3]> = self.pixels.clone();
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    }

    /// How many pixels are the scope's trace colour.
    fn trace_pixels(&self) -> usize {
        self.pixels
            .iter()
            .filter(|pixel| {
                pixel
                    .iter()
                    .zip(TRACE_RGB)
                    .all(|(&value, target)| value.abs_diff(target) <= TRACE_TOLERANCE)
            })
            .count()
    }
}

/// A child process that is stopped (SIGTERM, then SIGKILL after [`STOP_TIMEOUT`]) when dropped.
struct Stopped {
    name: &'static str,
    child: Option<Child>,
}

impl Stopped {
    fn spawn(name: &'static str, command: &mut Command) -> anyhow::Result<Self> {
        let child = command
            .spawn()
            .with_context(|| format!("starting {name}"))?;
        Ok(Self {
            name,
            child: Some(child),
        })
    }

    fn pid(&self) -> u32 {
        self.child.as_ref().map_or(0, Child::id)
    }

    /// Fails, with the end of its logs, if the process has ended.
    fn check_running(&mut self, logs: &[PathBuf]) -> anyhow::Result<()> {
        if let Some(child) = &mut self.child {
            if let Some(status) = child.try_wait()? {
                let tail: String = logs.iter().map(|log| read_lossy(log)).collect();
                let tail = &tail[tail.len().saturating_sub(2000)..];
                bail!("{} exited ({status}):\n{tail}", self.name);
            }
        }
        Ok(())
    }

    /// SIGTERM, then SIGKILL if it has not ended in time; fails if it had to be killed.
    fn stop(&mut self) -> anyhow::Result<()> {
        let Some(mut child) = self.child.take() else {
            return Ok(());
        };
        if child.try_wait()?.is_some() {
            return Ok(());
        }
        // std offers only SIGKILL; kill(1) sends SIGTERM, so the process can clean up.
        let _ = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let started = Instant::now();
        while started.elapsed() < STOP_TIMEOUT {
            if child.try_wait()?.is_some() {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        child.kill()?;
        child.wait()?;
        bail!(
            "{} did not end within {} s of SIGTERM and was killed",
            self.name,
            STOP_TIMEOUT.as_secs()
        )
    }
}

impl Drop for Stopped {
    fn drop(&mut self) {
        if let Err(error) = self.stop() {
            eprintln!("{error:#}");
        }
    }
}

/// A virtual X server on a display number it picks itself (`-displayfd`), stopped when dropped.
struct Xvfb {
    display: String,
    // Dropped after `display` is no longer needed: stops the server.
    _process: Stopped,
}

impl Xvfb {
    fn start(log: &Path) -> anyhow::Result<Self> {
        let mut process = Stopped::spawn(
            "Xvfb",
            Command::new("Xvfb")
                .args(["-displayfd", "1", "-screen", "0", "1024x768x24"])
                .args(["+extension", "GLX", "-nolisten", "tcp"])
                .stdin(Stdio::null())
                .stdout(Stdio::piped())
                .stderr(File::create(log)?),
        )?;
        // Xvfb writes its display number and a newline to stdout once it accepts clients (and
        // keeps the pipe open); it ends the pipe if it fails to start.
        let mut number = String::new();
        if let Some(stdout) = process
            .child
            .as_mut()
            .and_then(|child| child.stdout.as_mut())
        {
            BufReader::new(stdout).read_line(&mut number)?;
        }
        let number = number.trim();
        if number.is_empty() {
            process.check_running(&[log.to_owned()])?;
            bail!("Xvfb did not say which display it took");
        }
        Ok(Self {
            display: format!(":{number}"),
            _process: process,
        })
    }
}

/// CPU seconds a process used over a while, in all and per thread.
struct CpuTime {
    total_s: f64,
    /// Each thread that ran, busiest first: its name and tid, and its seconds.
    threads: Vec<(String, f64)>,
}

impl CpuTime {
    /// The seconds of Mesa's software rasteriser threads (llvmpipe-N), which a GPU would do.
    fn software_gl_s(&self) -> f64 {
        self.threads
            .iter()
            .filter(|(name, _)| name.starts_with("llvmpipe"))
            .map(|(_, seconds)| seconds)
            .sum()
    }
}

impl std::fmt::Display for CpuTime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:.2} s", self.total_s)?;
        let busy: Vec<String> = self
            .threads
            .iter()
            .filter(|(_, seconds)| *seconds > 0.0)
            .map(|(name, seconds)| format!("{name} {seconds:.2} s"))
            .collect();
        if !busy.is_empty() {
            write!(f, " ({})", busy.join(", "))?;
        }
        Ok(())
    }
}

/// The CPU time `pid` uses over `window`, calling `during` every 50 ms meanwhile.
fn cpu_over(
    pid: u32,
    window: Duration,
    mut during: impl FnMut() -> anyhow::Result<()>,
) -> anyhow::Result<CpuTime> {
    let ticks_per_s: f64 = String::from_utf8(
        Command::new("getconf")
            .arg("CLK_TCK")
            .output()
            .context("running getconf CLK_TCK")?
            .stdout,
    )?
    .trim()
    .parse()
    .context("getconf CLK_TCK is not a number")?;
    let process = PathBuf::from(format!("/proc/{pid}/stat"));
    let (total_before, threads_before) = (cpu_ticks(&process)?.1, thread_ticks(pid)?);
    let started = Instant::now();
    while started.elapsed() < window {
        during()?;
        std::thread::sleep(Duration::from_millis(50));
    }
    let (total_after, threads_after) = (cpu_ticks(&process)?.1, thread_ticks(pid)?);
    let seconds = |before: u64, after: u64| after.saturating_sub(before) as f64 / ticks_per_s;
    let mut threads: Vec<(String, f64)> = threads_after
        .into_iter()
        .map(|(tid, (name, after))| {
            let before = threads_before.get(&tid).map_or(0, |(_, ticks)| *ticks);
            (format!("{name} [{tid}]"), seconds(before, after))
        })
        .collect();
    threads.sort_by(|a, b| b.1.total_cmp(&a.1));
    Ok(CpuTime {
        total_s: seconds(total_before, total_after),
        threads,
    })
}

/// Every thread of `pid`: its name and CPU ticks, by thread id.
fn thread_ticks(pid: u32) -> anyhow::Result<std::collections::BTreeMap<u32, (String, u64)>> {
    let mut threads = std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(format!("/proc/{pid}/task"))
        .with_context(|| format!("listing the threads of {pid} (has the app ended?)"))?
    {
        let entry = entry?;
        let Ok(tid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        // A thread may end between the listing and the read.
        if let Ok(ticks) = cpu_ticks(&entry.path().join("stat")) {
            threads.insert(tid, ticks);
        }
    }
    Ok(threads)
}

/// The name and utime + stime (in clock ticks) of a /proc stat file: fields 14 and 15, counted
/// after the name's closing parenthesis, as the name (field 2) may hold spaces.
fn cpu_ticks(stat: &Path) -> anyhow::Result<(String, u64)> {
    let text = std::fs::read_to_string(stat)
        .with_context(|| format!("reading {} (has the app ended?)", stat.display()))?;
    let (head, rest) = text
        .rsplit_once(')')
        .with_context(|| format!("{} has no name field", stat.display()))?;
    let name = head.split_once('(').map_or("", |(_, name)| name).to_owned();
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // After the name, field 3 (the state) comes first: utime is field 14, so index 11.
    let field = |index: usize| -> anyhow::Result<u64> {
        fields
            .get(index)
            .and_then(|value| value.parse().ok())
            .with_context(|| format!("{} has no field {}", stat.display(), index + 3))
    };
    Ok((name, field(11)? + field(12)?))
}

//! `cargo xtask screenshots`: the editor in a real window. The standalone app runs under Xvfb
//! (a virtual X server) with the dummy audio backend; the editor is shot idle, then while a
//! phone's gravity over OSC (loopback UDP) holds the bottle at 135°. Writes
//! docs/editor-idle.png and docs/editor-pouring.png. Needs Xvfb, imagemagick's `import` and
//! `identify`, and xdotool (Debian: xvfb, imagemagick, xdotool).

use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use rosc::{encoder, OscMessage, OscPacket, OscType};

/// The app's window title (the plugin's name).
const WINDOW_NAME: &str = "^Sake Glug$";
/// A phone lying so that its +y axis (the bottle's base-to-mouth axis) is 135° from up: the
/// gravity GyrOSC reports, pointing to the earth (README "Phones and other sensors over OSC").
const GRAVITY_AT_135: [f32; 3] = [0.0, std::f32::consts::FRAC_1_SQRT_2, -0.707_106_77];
/// How long the pour runs before the shot: the scope shows the last 0.6 s, full of glugs by then.
const POURING_FOR: Duration = Duration::from_millis(1_500);
/// How long the app's CPU time is counted, idle and then pouring (a full bottle glugs for about
/// 3.5 s at 135°).
const COUNTED_FOR: Duration = Duration::from_secs(3);

/// A child process ended when the guard goes, whatever happened: asked with SIGTERM first, so
/// that Xvfb removes its socket and lock file, killed if it has not ended a second later.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = Command::new("kill")
            .args(["-TERM", &self.0.id().to_string()])
            .status();
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(1) {
            if let Ok(Some(_)) = self.0.try_wait() {
                return;
            }
            sleep(Duration::from_millis(20));
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Runs the app under Xvfb, writes the two screenshots under docs/, and returns a sentence on
/// the app's CPU time idle and pouring (whether the editor repaints only on change).
pub fn screenshots(app: &Path) -> nice_plug_xtask::Result<String> {
    for (tool, package) in [
        ("Xvfb", "xvfb"),
        ("import", "imagemagick"),
        ("identify", "imagemagick"),
        ("xdotool", "xdotool"),
    ] {
        let found = Command::new("sh")
            .args(["-c", &format!("command -v {tool}")])
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|status| status.success());
        if !found {
            bail!("`{tool}` is missing: install the Debian package {package}");
        }
    }
    let display = free_display().context("no free X display number in :90..:189")?;
    let _xvfb = spawn(
        Command::new("Xvfb").arg(&display).args([
            "-screen",
            "0",
            "1024x768x24",
            "+extension",
            "GLX",
            "-nolisten",
            "tcp",
        ]),
        "Xvfb",
    )?;
    let socket = PathBuf::from(format!("/tmp/.X11-unix/X{}", &display[1..]));
    wait_for(Duration::from_secs(10), "Xvfb to listen", || {
        Ok(socket.exists().then_some(()))
    })?;

    let port = UdpSocket::bind("127.0.0.1:0")?.local_addr()?.port();
    let app = spawn(
        Command::new(app)
            .env("DISPLAY", &display)
            .args(["--backend", "dummy", "--osc-axis", "+y", "--osc-port"])
            .arg(port.to_string()),
        "the standalone app",
    )?;
    let window = wait_for(Duration::from_secs(20), "the app's window", || {
        let out = Command::new("xdotool")
            .env("DISPLAY", &display)
            .args(["search", "--name", WINDOW_NAME])
            .output()?;
        Ok(String::from_utf8_lossy(&out.stdout)
            .lines()
            .next()
            .map(str::to_owned))
    })?;

    let idle = Path::new("docs/editor-idle.png");
    wait_for(Duration::from_secs(20), "the editor to paint", || {
        shoot(&display, &window, idle)?;
        Ok((colours(idle)? > 16).then_some(()))
    })?;

    let idle_cpu = cpu_seconds_over(&app, COUNTED_FOR, || Ok(()))?;

    // The phone tilts the bottle; packets keep coming as a phone sends them.
    let sender = UdpSocket::bind("127.0.0.1:0")?;
    let gravity = encoder::encode(&OscPacket::Message(OscMessage {
        addr: "/gyrosc/grav".into(),
        args: GRAVITY_AT_135.iter().map(|g| OscType::Float(*g)).collect(),
    }))?;
    let start = Instant::now();
    let mut shot = false;
    let pouring_cpu = cpu_seconds_over(&app, COUNTED_FOR, || {
        sender.send_to(&gravity, ("127.0.0.1", port))?;
        if !shot && start.elapsed() >= POURING_FOR {
            shoot(&display, &window, Path::new("docs/editor-pouring.png"))?;
            shot = true;
        }
        Ok(())
    })?;
    if !shot {
        bail!("the pour ended before its screenshot");
    }
    println!("wrote docs/editor-idle.png and docs/editor-pouring.png");
    let seconds = COUNTED_FOR.as_secs_f64();
    Ok(format!(
        "the app used {idle_cpu:.2} s of CPU in {seconds} s upright and idle, \
         {pouring_cpu:.2} s in {seconds} s of pouring (software OpenGL included)"
    ))
}

/// The app's CPU time (user and system, in seconds) over `span`, calling `meanwhile` every
/// 50 ms.
fn cpu_seconds_over(
    app: &Running,
    span: Duration,
    mut meanwhile: impl FnMut() -> nice_plug_xtask::Result<()>,
) -> nice_plug_xtask::Result<f64> {
    let before = cpu_seconds(app)?;
    let start = Instant::now();
    while start.elapsed() < span {
        meanwhile()?;
        sleep(Duration::from_millis(50));
    }
    Ok(cpu_seconds(app)? - before)
}

/// utime + stime of /proc/<pid>/stat (fields 14 and 15, in clock ticks of 1/100 s on Linux).
fn cpu_seconds(app: &Running) -> nice_plug_xtask::Result<f64> {
    let stat = std::fs::read_to_string(format!("/proc/{}/stat", app.0.id()))?;
    // The command name (field 2) may hold spaces; the fields after it are plain numbers.
    let after_name = &stat[stat.rfind(')').context("no command name in /proc stat")? + 2..];
    let fields: Vec<&str> = after_name.split(' ').collect();
    let ticks: u64 = fields[11].parse::<u64>()? + fields[12].parse::<u64>()?;
    Ok(ticks as f64 / 100.0)
}

fn spawn(command: &mut Command, name: &'static str) -> nice_plug_xtask::Result<Running> {
    let child = command
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .with_context(|| format!("could not start {name}"))?;
    Ok(Running(child))
}

/// The first display number with neither a lock file nor a socket.
fn free_display() -> Option<String> {
    (90..190)
        .find(|n| {
            !Path::new(&format!("/tmp/.X{n}-lock")).exists()
                && !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
        })
        .map(|n| format!(":{n}"))
}

/// Polls `probe` every 100 ms until it gives a value, or fails naming `what` after `timeout`.
fn wait_for<T>(
    timeout: Duration,
    what: &str,
    mut probe: impl FnMut() -> nice_plug_xtask::Result<Option<T>>,
) -> nice_plug_xtask::Result<T> {
    let start = Instant::now();
    loop {
        if let Some(value) = probe()? {
            return Ok(value);
        }
        if start.elapsed() > timeout {
            bail!("gave up waiting for {what} after {} s", timeout.as_secs());
        }
        sleep(Duration::from_millis(100));
    }
}

fn shoot(display: &str, window: &str, to: &Path) -> nice_plug_xtask::Result<()> {
    let status = Command::new("import")
        .env("DISPLAY", display)
        .args(["-window", window])
        .arg(to)
        .status()?;
    if !status.success() {
        bail!("`import` could not shoot window {window} ({status})");
    }
    Ok(())
}

/// How many distinct colours a picture has: a window not painted yet has one or two.
fn colours(picture: &Path) -> nice_plug_xtask::Result<u64> {
    let out = Command::new("identify")
        .args(["-format", "%k"])
        .arg(picture)
        .output()?;
    Ok(String::from_utf8_lossy(&out.stdout).trim().parse()?)
}

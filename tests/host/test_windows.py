"""The Windows release of `cargo xtask dist` (target/dist/), checked under Wine as a Windows user
installs it: the installer run silently (`/S /PATH`) in a fresh Wine prefix puts the VST3 bundle
in `%CommonProgramFiles%\\VST3`, the CLAP plugin in `%CommonProgramFiles%\\CLAP`, and every other
file of the portable zip in `%ProgramFiles%\\Sake Glug`, registers its uninstaller with the
workspace's version and adds its `bin` to the PATH; the installed `sake-glug.exe` writes every
format of several scenes byte for byte as the Linux CLI writes them (Ogg Vorbis, whose C encoder
rounds as the platform's maths library does, decodes to the same length within -80 dB); a C program cross-compiled
against the installed header, import library and DLL writes the Linux CLI's (and so the Linux
library's) samples bit for bit; the installed standalone app opens its editor (under Xvfb) and
quits when its window is closed; the uninstaller then leaves `Program Files` as it was and the
PATH as it was. The Python wheel beside them is checked as files only (no Windows CPython can be
had here to import it, under Wine or elsewhere): its tag is win_amd64 for abi3, it holds the
package's Python files and its extension module, a DLL that exports the module's PyInit_ and links
only Windows' own DLLs and python3.dll.

Needs the installer that `cargo xtask test` builds (`cargo xtask dist windows --profile
windows-test`, in target/dist-windows-test; SAKE_GLUG_WINDOWS_DIST names another folder, such as
target/dist for the shipped release), Debian's wine64, gcc-mingw-w64-x86-64 and xvfb, and
python-xlib (tests/host/requirements.txt) to close the editor's window as a window manager would.
Where one is missing the module is skipped, but under CI (`$CI` set), which installs them all,
it fails.
"""

import os
import re
import shutil
import subprocess
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from scipy.io import wavfile

# An X display of our own (Xvfb) for the app's window, as the Linux app's tests have it.
from test_standalone import display  # noqa: F401

REPO = Path(__file__).resolve().parents[2]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
# The installer and zip `cargo xtask test` builds (`cargo xtask dist windows --profile
# windows-test`); SAKE_GLUG_WINDOWS_DIST=target/dist checks the shipped release's instead.
TEST_DIST = TARGET / "dist-windows-test"
DIST = Path(os.environ.get("SAKE_GLUG_WINDOWS_DIST", TEST_DIST))
# The Linux CLI the Windows one is compared with: the release build's, or SAKE_GLUG_CLI's.
CLI = Path(os.environ.get("SAKE_GLUG_CLI", TARGET / "release" / "sake-glug"))
VERSION = tomllib.loads((REPO / "Cargo.toml").read_text())["workspace"]["package"]["version"]
STEM = f"sake-glug-{VERSION}-windows-x86_64"
INSTALLER = DIST / f"{STEM}-setup.exe"
ZIP = DIST / f"{STEM}.zip"
# abi3 (python/Cargo.toml): one wheel for every CPython from 3.8 on, linked to python3.dll.
WHEEL = DIST / f"sake_glug-{VERSION}-cp38-abi3-win_amd64.whl"
# Debian's wine64 installs no `wine64` on PATH: the loader is here.
WINE = Path("/usr/lib/wine/wine64")
WINESERVER = Path("/usr/lib/wine/wineserver")
MINGW_GCC = "x86_64-w64-mingw32-gcc"
MINGW_OBJDUMP = "x86_64-w64-mingw32-objdump"
# Where a 64-bit Windows keeps programs and the files hosts share, inside a prefix's drive C:.
PROGRAM_FILES = "drive_c/Program Files"
INSTALL_DIR = f"{PROGRAM_FILES}/Sake Glug"
COMMON_FILES = f"{PROGRAM_FILES}/Common Files"
UNINSTALL_KEY = r"HKLM\Software\Microsoft\Windows\CurrentVersion\Uninstall\Sake Glug"
ENVIRONMENT_KEY = r"HKLM\System\CurrentControlSet\Control\Session Manager\Environment"
SCENES = ["water", "syrup", "glass-bottle", "large-bottle"]


def need(present, what, package):
    if not present:
        if os.environ.get("CI"):
            pytest.fail(f"{what} is not installed (Debian: {package}); .ci/run installs it")
        pytest.skip(f"{what} is not installed (Debian: {package})")


def run(command, **options):
    done = subprocess.run(command, capture_output=True, text=True, **options)
    assert done.returncode == 0, f"{command} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}"
    return done.stdout


class Wine:
    """A throw-away Wine prefix, and how a program runs in it."""

    def __init__(self, prefix):
        self.prefix = prefix
        # No questions: Wine Mono and Gecko are not installed (nothing here needs .NET or HTML).
        self.env = dict(os.environ, WINEPREFIX=str(prefix), WINEDEBUG="-all",
                        WINEDLLOVERRIDES="mscoree=;mshtml=")
        self.env.pop("DISPLAY", None)

    def run(self, *command, cwd=None, env=None):
        """Runs a Windows program to its end, and every process it started."""
        done = subprocess.run([str(WINE), *map(str, command)], cwd=cwd, env={**self.env, **(env or {})},
                              capture_output=True, stdin=subprocess.DEVNULL)
        self.wait()
        return done

    def wait(self):
        subprocess.run([str(WINESERVER), "-w"], env=self.env, check=True)

    def registry_value(self, key, name):
        done = self.run("reg", "query", key, "/v", name)
        if done.returncode != 0:
            return None
        for line in done.stdout.decode(errors="replace").splitlines():
            parts = line.strip().split(None, 2)
            if len(parts) >= 2 and parts[0].lower() == name.lower():
                return parts[2] if len(parts) == 3 else ""
        return None

    def key_exists(self, key):
        return self.run("reg", "query", key).returncode == 0

    def files(self, folder):
        """Every file and folder under `folder` of drive C:, relative to the prefix."""
        root = self.prefix / folder
        return {path.relative_to(self.prefix).as_posix() for path in root.rglob("*")}


def require_release():
    """Skips where the Windows release is not built, but fails under CI, which must build it:
    `cargo xtask test` builds it where MinGW-w64 and NSIS are installed (CI installs them)."""
    if not INSTALLER.exists():
        missing = f"{INSTALLER} is not built: `cargo xtask dist windows --profile windows-test` builds it"
        if os.environ.get("CI"):
            pytest.fail(missing)
        pytest.skip(missing)


@pytest.fixture(scope="module")
def wine(tmp_path_factory):
    require_release()
    need(WINE.exists(), "wine64", "wine64")
    need(shutil.which(MINGW_GCC), MINGW_GCC, "gcc-mingw-w64-x86-64")
    wine = Wine(tmp_path_factory.mktemp("wine") / "prefix")
    done = wine.run("wineboot", "--init")
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    # Rust's standard library (1.78 and later) imports ProcessPrng from bcryptprimitives.dll,
    # which Windows 10 and later have and Wine 8 lacks: without this stand-in every Rust program
    # fails to start under Wine with status c0000135. It goes into the throw-away prefix's
    # system32, the place Windows keeps it, and never into the release (process_prng.c).
    system32 = wine.prefix / "drive_c/windows/system32"
    assert not (system32 / "bcryptprimitives.dll").exists(), "this Wine has ProcessPrng: drop the shim"
    run([MINGW_GCC, "-shared", "-O2", "-o", str(system32 / "bcryptprimitives.dll"),
         str(REPO / "tests/host/windows/process_prng.c"), "-ladvapi32"])
    yield wine
    subprocess.run([str(WINESERVER), "-k"], env=wine.env)


@pytest.fixture(scope="module")
def before(wine):
    """What Program Files and the PATH held before the installer ran."""
    return wine.files(PROGRAM_FILES), wine.registry_value(ENVIRONMENT_KEY, "Path")


@pytest.fixture(scope="module")
def installed(wine, before):
    done = wine.run(INSTALLER, "/S", "/PATH")
    assert done.returncode == 0, f"the installer failed ({done.returncode})"
    return wine


def zip_tree():
    """The portable zip's files, relative to its one top folder."""
    with zipfile.ZipFile(ZIP) as archive:
        names = [name for name in archive.namelist() if not name.endswith("/")]
    assert names and all(name.startswith(f"{STEM}/") for name in names), names[:3]
    return {name.removeprefix(f"{STEM}/") for name in names}


def installed_place(inside):
    """Where the installer puts a file of the zip's tree, as the tree's README says."""
    first, _, rest = inside.partition("/")
    if first in ("CLAP", "VST3"):
        return f"{COMMON_FILES}/{inside}"
    return f"{INSTALL_DIR}/{inside}"


def exports(dll):
    table = run([MINGW_OBJDUMP, "-p", str(dll)])
    return set(re.findall(r"^\s*\[\s*\d+\]\s+(\S+)\s*$", table, re.MULTILINE))


def test_installer_puts_each_file_where_windows_hosts_and_users_look(installed, before):
    files_before, _ = before
    new = installed.files(PROGRAM_FILES) - files_before
    new_files = {path for path in new if (installed.prefix / path).is_file()}
    expected = {installed_place(inside) for inside in zip_tree()} | {f"{INSTALL_DIR}/uninstall.exe"}
    assert new_files == expected, (
        f"installed but not in the zip: {sorted(new_files - expected)[:5]}; "
        f"in the zip but not installed: {sorted(expected - new_files)[:5]}"
    )
    vst3 = installed.prefix / COMMON_FILES / "VST3/Sake Glug.vst3/Contents/x86_64-win/Sake Glug.vst3"
    clap = installed.prefix / COMMON_FILES / "CLAP/Sake Glug.clap"
    assert "GetPluginFactory" in exports(vst3)
    assert "clap_entry" in exports(clap)
    for program in ["sake-glug.exe", "sake-glug-standalone.exe", "sake_glug.dll"]:
        assert (installed.prefix / INSTALL_DIR / "bin" / program).is_file(), program
    # No test-only file reaches a user: the ProcessPrng stand-in is the prefix's, not the release's.
    assert not any(path.lower().endswith("bcryptprimitives.dll") for path in new_files)


def test_installer_registers_its_version_and_the_path(installed, before):
    _, path_before = before
    assert installed.registry_value(UNINSTALL_KEY, "DisplayVersion") == VERSION
    assert installed.registry_value(UNINSTALL_KEY, "DisplayName") == "Sake Glug"
    path = installed.registry_value(ENVIRONMENT_KEY, "Path")
    assert path == f"{path_before};C:\\Program Files\\Sake Glug\\bin", path


def test_every_product_reports_the_workspaces_version(installed):
    for program in ["sake-glug.exe", "sake-glug-standalone.exe"]:
        done = installed.run(installed.prefix / INSTALL_DIR / "bin" / program, "--version")
        assert done.returncode == 0, done.stderr.decode(errors="replace")
        assert done.stdout.decode().split() == [program.removesuffix(".exe"), VERSION]


def format_names():
    """Every format `render --formats` takes, as the Linux CLI's help lists them."""
    text = " ".join(run([str(CLI), "render", "--help"]).split())
    listed = re.search(r"With --out-dir: the formats to write \(([^)]*)\)", text)
    assert listed, "render --help lists no formats"
    names = re.split(r",\s*|\s+or\s+", listed.group(1))
    assert len(names) >= 10, names
    return [name.strip() for name in names if name.strip()]


def test_installed_cli_writes_every_format_byte_for_byte_as_linux(installed, tmp_path):
    assert CLI.exists(), f"{CLI} is missing: cargo xtask dist builds it"
    formats = ",".join(format_names())
    for scene in SCENES:
        shutil.copy(REPO / "presets" / f"{scene}.toml", tmp_path / f"{scene}.toml")
    scenes = [f"{scene}.toml" for scene in SCENES]
    run([str(CLI), "render", *scenes, "--out-dir", "linux", "--formats", formats], cwd=tmp_path)
    done = installed.run(installed.prefix / INSTALL_DIR / "bin/sake-glug.exe", "render", *scenes,
                         "--out-dir", "windows", "--formats", formats, cwd=tmp_path)
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    linux = sorted(path.name for path in (tmp_path / "linux").iterdir())
    windows = sorted(path.name for path in (tmp_path / "windows").iterdir())
    assert windows == linux and len(linux) >= len(SCENES) * 10, (windows, linux)
    # Ogg Vorbis alone is compared by its sound (below): its encoder is libvorbis, C code whose
    # float maths comes from the platform's C library, so its bit allocation differs in places.
    differ = [name for name in linux if not name.endswith(".ogg")
              and (tmp_path / "linux" / name).read_bytes() != (tmp_path / "windows" / name).read_bytes()]
    assert not differ, f"{len(differ)} of {len(linux)} files differ from Linux's: {differ}"
    oggs = [name for name in linux if name.endswith(".ogg")]
    assert len(oggs) == len(SCENES), oggs
    for name in oggs:
        linux_sound, windows_sound = decoded(tmp_path / "linux" / name), decoded(tmp_path / "windows" / name)
        assert windows_sound.shape == linux_sound.shape, (name, windows_sound.shape, linux_sound.shape)
        error_db = 20 * np.log10(rms(windows_sound - linux_sound) / rms(linux_sound))
        assert error_db < OGG_ERROR_DB, f"{name}: Windows' Ogg is {error_db:.1f} dB from Linux's"


# How near a Windows Ogg Vorbis must decode to the Linux one, relative to its level: far below
# the codec's own error (measured here: -86 to -145 dB for the scenes above).
OGG_ERROR_DB = -80


def decoded(path):
    from pedalboard.io import AudioFile

    with AudioFile(str(path)) as file:
        return file.read(file.frames)


def rms(samples):
    return np.sqrt(np.mean(np.square(samples, dtype=np.float64)))


def read_f32(path):
    rate, samples = wavfile.read(path)
    assert rate == 48000 and samples.dtype == np.float32 and samples.ndim == 1
    return samples


def test_c_program_against_the_installed_dll_gives_the_linux_librarys_samples(installed, tmp_path):
    # The Linux CLI's pour at f32: the Linux library's samples, bit for bit (test_capi.py).
    run([str(CLI), "render", "-o", str(tmp_path / "linux.wav"), "--sample-format", "f32"])
    source = REPO / "examples/c/pour.c"
    # Built as a Windows user of the installed library builds it: its header and import library.
    home = installed.prefix / INSTALL_DIR
    run([MINGW_GCC, "-std=c11", "-I", str(home / "include"), str(source), "-L", str(home / "lib"),
         "-lsake_glug", "-o", str(tmp_path / "pour.exe")])
    # The DLL is found on the PATH, in the installed bin folder, as the installer set it.
    done = installed.run(tmp_path / "pour.exe", "windows.wav", cwd=tmp_path)
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    linux, windows = read_f32(tmp_path / "linux.wav"), read_f32(tmp_path / "windows.wav")
    assert np.abs(linux).max() > 0.01
    assert windows.shape == linux.shape
    differ = np.flatnonzero(windows.view(np.uint32) != linux.view(np.uint32))
    assert differ.size == 0, f"{differ.size} samples differ, the first at {differ[:1]}"


def windows_named(display, name):
    from Xlib import X, display as xdisplay

    connection = xdisplay.Display(display)
    found = []
    pending = [connection.screen().root]
    while pending:
        window = pending.pop()
        try:
            if window.get_wm_name() == name and window.get_attributes().map_state == X.IsViewable:
                found.append(window.id)
            pending.extend(window.query_tree().children)
        except Exception:  # a window that went away while we looked
            continue
    connection.close()
    return found


def close_window(display, window_id):
    """What a window manager sends when the window's close button is clicked."""
    from Xlib import X, display as xdisplay
    from Xlib.protocol import event

    connection = xdisplay.Display(display)
    window = connection.create_resource_object("window", window_id)
    protocols = connection.intern_atom("WM_PROTOCOLS")
    delete = connection.intern_atom("WM_DELETE_WINDOW")
    message = event.ClientMessage(window=window, client_type=protocols, data=(32, [delete, X.CurrentTime, 0, 0, 0]))
    window.send_event(message, event_mask=X.NoEventMask)
    connection.sync()
    connection.close()


def test_standalone_app_opens_its_editor_and_quits_when_it_is_closed(installed, display):
    pytest.importorskip("Xlib", reason="python-xlib (tests/host/requirements.txt)")
    app = installed.prefix / INSTALL_DIR / "bin/sake-glug-standalone.exe"
    process = subprocess.Popen([str(WINE), str(app), "--backend", "dummy"],
                               env={**installed.env, "DISPLAY": display},
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    try:
        found = []
        # Bounded by a count of looks, not by the machine's speed: Wine starts slowly when busy.
        for _ in range(600):
            assert process.poll() is None, f"the app exited ({process.returncode}): {process.stdout.read().decode(errors='replace')}"
            found = windows_named(display, "Sake Glug")
            if found:
                break
            subprocess.run(["sleep", "0.1"])
        assert found, "the app's editor window never appeared"
        close_window(display, found[0])
        output, _ = process.communicate(timeout=120)
        assert process.returncode == 0, f"the app ended with {process.returncode}: {output.decode(errors='replace')[-2000:]}"
    finally:
        if process.poll() is None:
            process.kill()
        installed.wait()


def test_uninstaller_removes_everything_it_installed(installed, before):
    files_before, path_before = before
    done = installed.run(installed.prefix / INSTALL_DIR / "uninstall.exe", "/S")
    assert done.returncode == 0
    left = installed.files(PROGRAM_FILES) - files_before
    assert not left, f"left after uninstalling: {sorted(left)[:10]}"
    assert not installed.key_exists(UNINSTALL_KEY)
    assert installed.registry_value(ENVIRONMENT_KEY, "Path") == path_before


def test_readme_names_this_versions_windows_artefacts():
    readme = (REPO / "README.md").read_text()
    for artefact in (INSTALLER.name, ZIP.name, WHEEL.name):
        assert artefact in readme, f"README.md's install section does not name {artefact}"


# The DLLs a Windows 10 or later has in its system folder that a Rust program built with MinGW-w64
# may link (the C runtime msvcrt.dll among them); with python3.dll, all the wheel's module may
# need. A MinGW runtime DLL (libgcc_s_seh-1.dll, libwinpthread-1.dll) or a versioned
# python3X.dll would make it fail to load on a user's machine.
WINDOWS_SYSTEM_DLLS = {"kernel32.dll", "ntdll.dll", "msvcrt.dll", "bcryptprimitives.dll", "advapi32.dll",
                       "userenv.dll", "ws2_32.dll", "bcrypt.dll", "user32.dll", "shell32.dll", "ole32.dll"}


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """The wheel's files, unpacked."""
    require_release()
    need(shutil.which(MINGW_OBJDUMP), MINGW_OBJDUMP, "binutils-mingw-w64-x86-64")
    assert WHEEL.exists(), f"{WHEEL.name} is not beside {INSTALLER.name}: `cargo xtask dist windows` writes it"
    unpacked = tmp_path_factory.mktemp("wheel")
    with zipfile.ZipFile(WHEEL) as archive:
        archive.extractall(unpacked)
    return unpacked


def test_wheel_is_tagged_for_64_bit_windows_and_every_cpython_from_3_8(wheel):
    info = wheel / f"sake_glug-{VERSION}.dist-info"
    fields = [line.partition(": ") for line in (info / "WHEEL").read_text().splitlines()]
    assert [value for key, _, value in fields if key == "Tag"] == ["cp38-abi3-win_amd64"]
    assert ("Root-Is-Purelib", ": ", "false") in fields
    metadata = (info / "METADATA").read_text().splitlines()
    assert f"Version: {VERSION}" in metadata and "Name: sake_glug" in metadata


def test_wheel_holds_the_packages_python_files_and_its_extension_module(wheel):
    import base64
    import hashlib

    package = {path.relative_to(wheel).as_posix() for path in (wheel / "sake_glug").rglob("*") if path.is_file()}
    # The Python files are the repository's, as the Linux wheel has them; the module is a .pyd.
    tracked = run(["git", "ls-files", "sake_glug"], cwd=REPO / "python").split()
    assert package == set(tracked) | {"sake_glug/_sake_glug.pyd"}, sorted(package)
    for name in tracked:
        assert (wheel / name).read_bytes() == (REPO / "python" / name).read_bytes(), name
    # pip refuses a wheel whose RECORD does not match its files.
    record = (wheel / f"sake_glug-{VERSION}.dist-info/RECORD").read_text().splitlines()
    listed = {}
    for line in record:
        name, digest, _ = line.rsplit(",", 2)
        listed[name] = digest
    for name in package:
        digest = base64.urlsafe_b64encode(hashlib.sha256((wheel / name).read_bytes()).digest()).rstrip(b"=")
        assert listed.get(name) == f"sha256={digest.decode()}", name


def test_wheels_module_exports_its_init_and_links_only_windows_and_python3(wheel):
    module = wheel / "sake_glug/_sake_glug.pyd"
    table = run([MINGW_OBJDUMP, "-p", str(module)])
    assert "PyInit__sake_glug" in exports(module)
    linked = {name.lower() for name in re.findall(r"^\s*DLL Name: (\S+)\s*$", table, re.MULTILINE)}
    assert "python3.dll" in linked, linked
    # api-ms-win-*: Windows' API sets, which every Windows 10 resolves to its own DLLs.
    foreign = {name for name in linked - WINDOWS_SYSTEM_DLLS - {"python3.dll"} if not name.startswith("api-ms-win-")}
    assert not foreign, f"the module links DLLs that Windows does not have: {sorted(foreign)}"

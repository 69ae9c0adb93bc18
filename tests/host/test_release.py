"""The release of `cargo xtask dist` (target/dist/), checked on the artefacts as a user installs
them: the Debian package installed with dpkg (and purged at the end, even when a check fails),
the tarball's install.sh into a throw-away HOME (and --uninstall), the wheel into a fresh venv
with no cargo on PATH. From each install: `sake-glug render` from PATH, the VST3 in pedalboard
and the C example built through pkg-config give the build's CLI's samples bit for bit; every man
page renders; bash completes `sake-glug ren` to `render`; the installed CLI runs the installed
study spec (shortened) on a JACK server of its own; removing it leaves no file. lintian
finds no error in the .deb, auditwheel accepts the wheel as manylinux, and every product reports
the workspace's version.

Needs `cargo xtask dist` (run by `cargo xtask test` before these tests), root for dpkg, Debian's
lintian, pkg-config, man-db, bash-completion and jackd2 (.ci/run installs them), and auditwheel
(tests/host/requirements.txt).
"""

import csv
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.io import wavfile

import test_vst3_matches_offline as vst3_check

REPO = Path(__file__).resolve().parents[2]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
RELEASE = TARGET / "release"
DIST = TARGET / "dist"
CLI = RELEASE / "sake-glug"
VERSION = tomllib.loads((REPO / "Cargo.toml").read_text())["workspace"]["package"]["version"]
DEB = DIST / f"sake-glug_{VERSION}_amd64.deb"
TARBALL = DIST / f"sake-glug-{VERSION}-linux-x86_64.tar.gz"
PACKAGE = "sake-glug"
VST3_NAME = "Sake Glug.vst3"


def need(tool, package):
    if shutil.which(tool) is None:
        if os.environ.get("CI"):
            pytest.fail(f"{tool} is not installed (Debian: {package}); .ci/run installs it")
        pytest.skip(f"{tool} is not installed (Debian: {package})")


def run(command, **options):
    done = subprocess.run(command, capture_output=True, text=True, **options)
    assert done.returncode == 0, f"{command} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}"
    return done.stdout


def the_wheel():
    # The Linux one: `cargo xtask dist windows` writes its win_amd64 wheel beside it.
    wheels = sorted(DIST.glob(f"sake_glug-{VERSION}-*linux*.whl"))
    assert len(wheels) == 1, f"one Linux wheel of {VERSION} expected in {DIST}, found {wheels}"
    return wheels[0]


def read_f32(path):
    rate, samples = wavfile.read(path)
    assert samples.dtype == np.float32 and samples.ndim == 1, (samples.dtype, samples.shape)
    assert rate == 48000
    return samples


def assert_bit_identical(samples, expected, what):
    assert samples.shape == expected.shape, f"{what}: {samples.shape} samples, the CLI {expected.shape}"
    differ = np.flatnonzero(samples.view(np.uint32) != expected.view(np.uint32))
    assert differ.size == 0, f"{what}: {differ.size} samples differ, the first at {differ[:1]}"


@pytest.fixture(scope="module")
def cli_pour(tmp_path_factory):
    """The build's CLI's built-in pour, 48 kHz f32: what every install must reproduce."""
    assert CLI.exists(), f"{CLI} is missing: cargo xtask dist builds it"
    path = tmp_path_factory.mktemp("cli") / "pour.wav"
    run([str(CLI), "render", "-o", str(path), "--sample-format", "f32"])
    samples = read_f32(path)
    assert np.abs(samples).max() > 0.01
    return samples


class Install:
    """Where an installed release put its files, and the environment a user of it has."""

    def __init__(self, name, bin_dir, lib_dir, man_dir, vst3, env, files):
        self.name = name
        self.bin_dir = bin_dir
        self.lib_dir = lib_dir
        self.man_dir = man_dir
        # The docs, beside the man pages: <share>/doc/sake-glug.
        self.doc_dir = man_dir.parents[1] / "doc" / PACKAGE
        self.vst3 = vst3
        self.env = env
        self.files = files

    def __repr__(self):
        return self.name


def deb_files():
    """Every file and link the .deb holds, as installed (absolute paths), folders left out."""
    archive = subprocess.run(["dpkg-deb", "--fsys-tarfile", str(DEB)], capture_output=True, check=True).stdout
    listing = subprocess.run(["tar", "-tv"], input=archive, capture_output=True, check=True).stdout.decode()
    files = []
    for line in listing.splitlines():
        if line.startswith("d"):
            continue
        name = line.split(maxsplit=5)[5].split(" -> ")[0]
        files.append(Path("/" + name.removeprefix("./")))
    return files


@pytest.fixture(scope="module")
def deb_install():
    assert DEB.exists(), f"{DEB} is missing: run `cargo xtask dist`"
    if os.geteuid() != 0:
        if os.environ.get("CI"):
            pytest.fail("installing the .deb needs root")
        pytest.skip("installing the .deb needs root")
    need("dpkg", "dpkg")
    files = deb_files()
    # A package left by an earlier run that was killed would hide what this one installs.
    subprocess.run(["dpkg", "--purge", PACKAGE], capture_output=True)
    run(["dpkg", "-i", str(DEB)])
    try:
        env = dict(os.environ)
        env.pop("LD_LIBRARY_PATH", None)
        env.pop("PKG_CONFIG_PATH", None)
        yield Install(
            "deb",
            Path("/usr/bin"),
            Path("/usr/lib/x86_64-linux-gnu"),
            Path("/usr/share/man/man1"),
            Path("/usr/lib/vst3") / VST3_NAME,
            env,
            files,
        )
    finally:
        run(["dpkg", "--purge", PACKAGE])
    left = [str(path) for path in files if path.exists() or path.is_symlink()]
    assert not left, f"dpkg --purge left {len(left)} files: {left[:5]}"


@pytest.fixture(scope="module")
def tarball_install(tmp_path_factory):
    assert TARBALL.exists(), f"{TARBALL} is missing: run `cargo xtask dist`"
    unpacked = tmp_path_factory.mktemp("unpacked")
    run(["tar", "-xzf", str(TARBALL), "-C", str(unpacked)])
    (folder,) = unpacked.iterdir()
    home = tmp_path_factory.mktemp("home")
    env = dict(os.environ, HOME=str(home))
    env.pop("XDG_DATA_HOME", None)
    run([str(folder / "install.sh")], env=env)
    prefix = home / ".local"
    files = [path for path in home.rglob("*") if not path.is_dir()]
    env["PATH"] = f"{prefix / 'bin'}:{os.environ['PATH']}"
    env["PKG_CONFIG_PATH"] = str(prefix / "lib" / "pkgconfig")
    env["LD_LIBRARY_PATH"] = str(prefix / "lib")
    yield Install(
        "tarball",
        prefix / "bin",
        prefix / "lib",
        prefix / "share" / "man" / "man1",
        home / ".vst3" / VST3_NAME,
        env,
        files,
    )
    run([str(folder / "install.sh"), "--uninstall"], env=dict(os.environ, HOME=str(home)))
    left = sorted(str(path.relative_to(home)) for path in home.rglob("*"))
    assert not left, f"install.sh --uninstall left {left}"


@pytest.fixture(scope="module", params=["deb", "tarball"])
def install(request):
    return request.getfixturevalue(f"{request.param}_install")


def test_render_runs_from_path(install, cli_pour, tmp_path):
    found = shutil.which("sake-glug", path=install.env["PATH"])
    assert found == str(install.bin_dir / "sake-glug"), f"sake-glug on PATH is {found}"
    out = tmp_path / "pour.wav"
    run(["sake-glug", "render", "-o", str(out), "--sample-format", "f32"], env=install.env)
    assert_bit_identical(read_f32(out), cli_pour, f"{install}'s sake-glug")


def test_installed_vst3_renders_the_clis_samples(install, tmp_path):
    assert install.vst3.is_dir(), f"{install.vst3} is not installed"
    plugin = vst3_check.load_plugin(str(install.vst3), initialization_timeout=0.2)
    scene = tmp_path / "scene.toml"
    scene.write_text(vst3_check.scene_toml("pour_at_135"))
    wav = tmp_path / "offline.wav"
    run([str(CLI), "render", str(scene), "-o", str(wav)])
    offline = read_f32(wav).astype(np.float64)
    vst3_check.load_scene(plugin, "pour_at_135")
    output = vst3_check.render(plugin, 512)
    assert np.max(np.abs(offline)) > 0.01
    assert np.array_equal(output[0], offline), f"{install}'s VST3 differs from the CLI"


def test_c_example_builds_through_pkg_config(install, cli_pour, tmp_path):
    need("cc", "gcc")
    need("pkg-config", "pkg-config")
    flags = run(["pkg-config", "--cflags", "--libs", PACKAGE], env=install.env).split()
    assert run(["pkg-config", "--modversion", PACKAGE], env=install.env).strip() == VERSION
    program = tmp_path / "pour"
    run(["cc", *map(str, sorted((REPO / "examples" / "c").glob("*.c"))), *flags, "-o", str(program)], env=install.env)
    # It links the installed library by its soname, which the loader finds there.
    needed = run(["ldd", str(program)], env=install.env)
    found = re.search(r"(libsake_glug\.so\.\d+) => (\S+)", needed)
    assert found, needed
    # (/lib is /usr/lib on a merged-/usr system.)
    assert Path(found[2]).resolve() == (install.lib_dir / found[1]).resolve(), needed
    out = tmp_path / "pour.wav"
    run([str(program), str(out)], env=install.env)
    assert_bit_identical(read_f32(out), cli_pour, f"{install}'s C library")


MARKDOWN_LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def broken_links(root):
    """Each link of the Markdown pages under `root` to a file that is not in that tree, as
    `page: target`: links to the web and to a page's own headings left out, code (spans and
    blocks, where a path is only named) too."""
    broken = []
    for page in sorted(root.rglob("*.md")):
        text = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)
        text = re.sub(r"`[^`\n]*`", "", text)
        for target in MARKDOWN_LINK.findall(text):
            if re.match(r"[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
                continue
            if not (page.parent / target.split("#")[0]).exists():
                broken.append(f"{page.relative_to(root)}: {target}")
    return broken


def test_every_link_of_the_installed_docs_is_installed(install):
    """The guide's study specs (experiments/, which `experiment --help` names too), the licence
    the README links: every page installed links only to what is installed beside it."""
    assert (install.doc_dir / "docs" / "guide" / "researcher.md").is_file(), install.doc_dir
    for spec in ["README.md", "paired-waves.toml", "viscosity-constant.toml"]:
        assert (install.doc_dir / "experiments" / spec).is_file(), f"{install}: experiments/{spec}"
    broken = broken_links(install.doc_dir)
    assert not broken, f"{install}: {len(broken)} links lead out of the installed docs: {broken}"


def subcommands():
    """The CLI's subcommands, as its help lists them."""
    help_text = run([str(CLI), "--help"])
    listed = help_text.split("Commands:")[1].split("Options:")[0]
    names = [line.split()[0] for line in listed.splitlines() if line.startswith("  ") and line.split()]
    return [name for name in names if name != "help"]


@pytest.fixture(scope="module")
def release_jack_server():
    from test_standalone import own_jack_server

    yield from own_jack_server("sakeglug-release", (CLI, "cargo xtask dist"))


def test_installed_cli_runs_the_installed_study_on_jack(install, release_jack_server, tmp_path):
    """A real study from the installed CLI, on the installed spec (shortened: its trials 0.2 s
    long, one repetition), played on a JACK server: a log row for each trial, with its frames."""
    installed = install.doc_dir / "experiments" / "paired-waves.toml"
    assert installed.is_file(), f"{install}: {installed} is not installed"
    spec = tomllib.loads(installed.read_text())
    lines = installed.read_text().splitlines()
    shortened = ["duration_s = 0.2" if l.startswith("duration_s") else
                 "gap_s = 0.1" if l.startswith("gap_s") else
                 "repetitions = 1" if l.startswith("repetitions") else l for l in lines]
    (tmp_path / "study.toml").write_text("\n".join(shortened) + "\n")
    trials = len(spec["stimuli"]) * (len(spec["stimuli"]) - 1)
    env = dict(install.env, JACK_DEFAULT_SERVER=release_jack_server)
    done = subprocess.run(
        ["sake-glug", "experiment", "study.toml", "--participant", "p1", "--log", "log.csv"],
        cwd=tmp_path, env=env, input="\n" + "1\n" * trials, capture_output=True, text=True,
        timeout=120,
    )
    assert done.returncode == 0, f"{install}'s sake-glug experiment:\n{done.stdout}\n{done.stderr}"
    rows = list(csv.DictReader(open(tmp_path / "log.csv")))
    assert len(rows) == trials, f"{len(rows)} rows for {trials} trials"
    frames = [int(row["first_onset_frame"]) for row in rows]
    assert frames == sorted(frames) and frames[0] >= 0, frames
    assert all(row.get("dry_run", "0") in ("0", "") for row in rows), rows[0]


def test_every_man_page_renders(install):
    need("man", "man-db")
    pages = sorted(install.man_dir.glob("sake-glug*.1.gz"))
    expected = {"sake-glug.1.gz"} | {f"sake-glug-{name}.1.gz" for name in subcommands()}
    assert expected <= {page.name for page in pages}, f"missing {expected - {page.name for page in pages}}"
    for page in pages:
        text = run(["man", "-l", str(page)], env=dict(install.env, MANPAGER="cat", MANWIDTH="80"))
        name = page.name.removesuffix(".1.gz")
        assert "NAME" in text and name in text, f"{page} renders as:\n{text[:400]}"
    # man finds a subcommand's page without being told where (man-db maps PATH to MANPATH).
    where = run(["man", "-w", "sake-glug-render"], env=install.env).strip()
    assert where == str(install.man_dir / "sake-glug-render.1.gz")


def test_bash_completes_the_subcommand(install):
    loader = Path("/usr/share/bash-completion/bash_completion")
    if not loader.exists():
        if os.environ.get("CI"):
            pytest.fail("bash-completion is not installed; .ci/run installs it")
        pytest.skip("bash-completion is not installed")
    # bash-completion loads the script by the command's name from where it looks by itself.
    script = f"""
source {loader}
__load_completion sake-glug || exit 3
function=$(complete -p sake-glug | sed -E 's/.*-F ([^ ]+) .*/\\1/')
COMP_WORDS=(sake-glug ren); COMP_CWORD=1; COMP_LINE='sake-glug ren'; COMP_POINT=${{#COMP_LINE}}
"$function" sake-glug ren sake-glug
printf '%s\\n' "${{COMPREPLY[@]}}"
"""
    completed = run(["bash", "-c", script], env=install.env).split()
    assert completed == ["render"], completed


def test_lintian_finds_no_error():
    need("lintian", "lintian")
    done = subprocess.run(["lintian", "--no-tag-display-limit", str(DEB)], capture_output=True, text=True)
    print(done.stdout)
    errors = [line for line in done.stdout.splitlines() if line.startswith("E:")]
    assert not errors, "\n".join(errors)


@pytest.fixture(scope="module")
def wheel_venv(tmp_path_factory):
    """A fresh venv with the wheel installed by pip from the file alone: no cargo on PATH, and
    only binary packages allowed, so nothing could be compiled."""
    venv = tmp_path_factory.mktemp("wheel") / "venv"
    run([sys.executable, "-m", "venv", str(venv)])
    path = ":".join(
        folder for folder in [str(venv / "bin"), "/usr/local/bin", "/usr/bin", "/bin"]
        if not (Path(folder) / "cargo").exists()
    )
    env = dict(os.environ, PATH=path, VIRTUAL_ENV=str(venv))
    env.pop("CARGO_TARGET_DIR", None)
    assert shutil.which("cargo", path=path) is None
    run([str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet", "--only-binary", ":all:", str(the_wheel())], env=env)
    return venv / "bin" / "python", env


def test_wheel_renders_the_clis_samples(wheel_venv, cli_pour, tmp_path):
    python, env = wheel_venv
    out = tmp_path / "samples.npy"
    code = f"import numpy, sake_glug; numpy.save({str(out)!r}, sake_glug.render())"
    run([str(python), "-c", code], env=env, cwd=tmp_path)
    samples = np.load(out)
    assert samples.dtype == np.float32
    assert_bit_identical(samples, cli_pour, "the wheel's sake_glug.render()")


def test_auditwheel_accepts_the_wheel_as_manylinux():
    auditwheel = Path(sys.executable).with_name("auditwheel")
    assert auditwheel.exists(), "auditwheel is missing: pip install -r tests/host/requirements.txt"
    wheel = the_wheel()
    shown = run([str(auditwheel), "show", str(wheel)])
    print(shown)
    policy = re.search(r'consistent\s+with\s+the\s+following\s+platform\s+tag:\s*"([^"]+)"', shown)
    assert policy, shown
    # The wheel is tagged with the policy auditwheel finds it meets: a manylinux one.
    assert policy.group(1).startswith("manylinux_"), policy.group(1)
    assert wheel.name.endswith(f"-{policy.group(1)}.whl"), (wheel.name, policy.group(1))


def test_every_product_reports_the_workspace_version(wheel_venv):
    reported = {}
    reported["sake-glug --version"] = run([str(CLI), "--version"]).split()[-1]
    reported["sake-glug-standalone --version"] = run([str(RELEASE / "sake-glug-standalone"), "--version"]).split()[-1]
    import ctypes

    library = ctypes.CDLL(str(RELEASE / "libsake_glug.so"))
    library.sake_glug_version.restype = ctypes.c_char_p
    reported["sake_glug_version()"] = library.sake_glug_version().decode()
    python, env = wheel_venv
    reported["sake_glug.__version__"] = run([str(python), "-c", "import sake_glug; print(sake_glug.__version__)"], env=env).strip()
    plugin = vst3_check.load_plugin(str(vst3_check.BUNDLE), initialization_timeout=0.2)
    reported["the VST3's version in pedalboard"] = plugin.version
    reported["the .deb's Version"] = run(["dpkg-deb", "-f", str(DEB), "Version"]).strip()
    wrong = {where: version for where, version in reported.items() if version != VERSION}
    assert not wrong, f"the workspace is {VERSION}; these differ: {wrong}"


def test_readme_and_changelog_name_this_version():
    readme = (REPO / "README.md").read_text()
    for artefact in (DEB.name, TARBALL.name, f"sake_glug-{VERSION}-"):
        assert artefact in readme, f"README.md's install section does not name {artefact}"
    releases = re.findall(r"^## \[(\d[^\]]*)\]", (REPO / "CHANGELOG.md").read_text(), re.M)
    assert releases[:1] == [VERSION], f"CHANGELOG.md's newest release is {releases[:1]}, not {VERSION}"

//! `cargo xtask dist`: a release in target/dist/, laid out from the binaries the build already
//! made (nothing is compiled here): the Debian package, the tarball with its install.sh, the
//! Python wheel, and THIRD-PARTY.md. One version for all, the workspace's (the xtask shares it).
//!
//! The Debian package is a tree laid out here and packed by `dpkg-deb`, its Depends computed by
//! `dpkg-shlibdeps` from what the binaries link: the tarball holds the same files from the same
//! layout code, and cargo-deb would build the binaries again (it runs cargo) and knows nothing of
//! the bundles, the wheel or the tarball.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;

/// The version of every product, the workspace's.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// The Debian package's name, the tarball's stem, the pkg-config module and the docs folder.
const PACKAGE: &str = "sake-glug";
/// The plugin's bundles are named after it: `Sake Glug.clap`, `Sake Glug.vst3`.
const PLUGIN: &str = "Sake Glug";
/// Debian's architecture and multiarch triplet of the machine the release is built for.
const DEB_ARCH: &str = "amd64";
const MULTIARCH: &str = "x86_64-linux-gnu";
/// The C library's file names; its soname (crates/capi/build.rs) carries the ABI version.
const SHARED_LIBRARY: &str = "libsake_glug.so";
const STATIC_LIBRARY: &str = "libsake_glug.a";
const MAINTAINER: &str =
    "The Sake Glug authors <maintainers@users.noreply.h-seed-9cfe8878.example>";
const SUMMARY: &str = "glug vibration of liquid poured from a sake bottle";
/// The licences cargo-about may accept are in about.toml, its template in about.hbs.
const ABOUT_TEMPLATE: &str = "about.hbs";

/// What the build made, where cargo, the bundler and maturin left it.
pub struct Built {
    pub cli: PathBuf,
    pub standalone: PathBuf,
    pub clap: PathBuf,
    pub vst3: PathBuf,
    pub shared: PathBuf,
    pub static_lib: PathBuf,
    pub wheel: PathBuf,
}

impl Built {
    /// The products' files under the target directory `target`; the wheel is the Linux one of
    /// this version in target/wheels (a Windows wheel that maturin was told to write there is not
    /// taken for it).
    pub fn under(target: &Path) -> anyhow::Result<Self> {
        let release = target.join("release");
        let wheels = target.join("wheels");
        let prefix = format!("sake_glug-{VERSION}-");
        let wheel = std::fs::read_dir(&wheels)
            .with_context(|| format!("{}: no wheel was built", wheels.display()))?
            .filter_map(|entry| entry.ok().map(|entry| entry.path()))
            .filter(|path| {
                path.file_name()
                    .and_then(|name| name.to_str())
                    .is_some_and(|name| {
                        name.starts_with(&prefix)
                            && name.ends_with(".whl")
                            && name.contains("linux")
                    })
            })
            .max_by_key(|path| path.metadata().and_then(|m| m.modified()).ok())
            .with_context(|| format!("no {prefix}*.whl in {}", wheels.display()))?;
        let built = Self {
            cli: release.join("sake-glug"),
            standalone: release.join("sake-glug-standalone"),
            clap: target.join(format!("bundled/{PLUGIN}.clap")),
            vst3: target.join(format!("bundled/{PLUGIN}.vst3")),
            shared: release.join(SHARED_LIBRARY),
            static_lib: release.join(STATIC_LIBRARY),
            wheel,
        };
        for path in [
            &built.cli,
            &built.standalone,
            &built.clap,
            &built.vst3,
            &built.shared,
            &built.static_lib,
        ] {
            anyhow::ensure!(
                path.exists(),
                "{} is missing: the build did not make it",
                path.display()
            );
        }
        Ok(built)
    }
}

/// Where each kind of file goes in a tree, relative to its root.
struct Layout {
    bin: &'static str,
    lib: String,
    include: &'static str,
    share: &'static str,
    doc: String,
    clap: &'static str,
    vst3: &'static str,
    /// The `prefix=` of the pkg-config file, and its libdir relative to it.
    pc_prefix: &'static str,
    pc_libdir: String,
    /// The licence's own file beside the docs (Debian's copyright file holds it instead).
    license_file: bool,
}

impl Layout {
    /// The Debian package: under /usr, the library in the multiarch folder, the plugins where
    /// hosts look for them without being told.
    fn debian() -> Self {
        Self {
            bin: "usr/bin",
            lib: format!("usr/lib/{MULTIARCH}"),
            include: "usr/include",
            share: "usr/share",
            doc: format!("usr/share/doc/{PACKAGE}"),
            clap: "usr/lib/clap",
            vst3: "usr/lib/vst3",
            pc_prefix: "/usr",
            pc_libdir: format!("lib/{MULTIARCH}"),
            // The installed README links to it; Debian's copyright file holds it too (lintian
            // only notes the extra file).
            license_file: true,
        }
    }

    /// The tarball: a prefix's folders (install.sh copies them under one), the plugins beside
    /// them (it copies them to ~/.clap and ~/.vst3). The pkg-config file finds its prefix from
    /// where it lies.
    fn tarball() -> Self {
        Self {
            bin: "bin",
            lib: "lib".into(),
            include: "include",
            share: "share",
            doc: format!("share/doc/{PACKAGE}"),
            clap: "clap",
            vst3: "vst3",
            pc_prefix: "${pcfiledir}/../..",
            pc_libdir: "lib".into(),
            license_file: true,
        }
    }
}

/// Writes the release into `out` (emptied first) from `built`: the .deb, the tarball, the wheel
/// and THIRD-PARTY.md. Returns the artefacts' paths.
pub fn dist(built: &Built, out: &Path) -> anyhow::Result<Vec<PathBuf>> {
    if out.exists() {
        std::fs::remove_dir_all(out).with_context(|| format!("emptying {}", out.display()))?;
    }
    let work = out.join("work");
    std::fs::create_dir_all(&work)?;
    let generated = work.join("generated");
    let notices = out.join("THIRD-PARTY.md");
    third_party(&notices, LINUX_TARGET, &LINUX_PRODUCTS)?;
    generate(built, &generated)?;

    // Where dpkg-shlibdeps expects a package's tree: debian/<package> beside debian/control.
    let deb_root = work.join("debian").join(PACKAGE);
    lay_out(built, &generated, &notices, &Layout::debian(), &deb_root)?;
    let deb = debian_package(&deb_root, out)?;

    let stem = format!("{PACKAGE}-{VERSION}-linux-x86_64");
    let tar_root = work.join(&stem);
    lay_out(built, &generated, &notices, &Layout::tarball(), &tar_root)?;
    let tarball = tarball(&tar_root, &stem, out)?;

    let wheel = out.join(built.wheel.file_name().context("the wheel has a name")?);
    std::fs::copy(&built.wheel, &wheel)?;
    std::fs::remove_dir_all(&work)?;
    Ok(vec![deb, tarball, wheel, notices])
}

/// A product as cargo builds it, for THIRD-PARTY.md: its title, manifest and features.
pub type Product = (&'static str, &'static str, &'static str);

/// The Linux products, for the target the Linux release is built for.
const LINUX_TARGET: &str = "x86_64-unknown-linux-gnu";
const LINUX_PRODUCTS: [Product; 4] = [
    ("The command line, `sake-glug`", "Cargo.toml", "ogg,audio"),
    (
        "The plugin (CLAP, VST3) and the standalone app, `sake-glug-standalone`",
        "crates/plugin/Cargo.toml",
        "editor,standalone",
    ),
    (
        "The C library, `libsake_glug`",
        "crates/capi/Cargo.toml",
        "",
    ),
    ("The Python package, `sake_glug`", "python/Cargo.toml", ""),
];

/// THIRD-PARTY.md: every crate (and the fonts, which epaint_default_fonts carries) that each
/// product links when built for `target`, with its licence's text, written by cargo-about from
/// the lock file; it fails when a crate's licence is not one that about.toml accepts.
pub fn third_party(notices: &Path, target: &str, products: &[Product]) -> anyhow::Result<()> {
    // cargo-about reads `cargo metadata`, which needs the sources of every platform's crates in
    // the lock file (Android's, Windows', macOS'), not only those a Linux build downloaded, and
    // run offline it cannot fetch them: so they are fetched first (nothing to do once they are).
    run_checked(Command::new(cargo()).args(["fetch", "--locked"]))?;
    let mut text = format!(
        "# Third-party licences of Sake Glug {VERSION}\n\n\
         Sake Glug itself is under the ISC licence (LICENSE). Each of its products links the \
         crates listed in its section, used under the licence named beside each, whose text \
         follows. Written by cargo-about (`cargo xtask dist`) from Cargo.lock.\n"
    );
    for &(product, manifest, features) in products {
        // Offline and against the lock file; --fail: a crate whose licence cannot be read fails.
        let mut args = vec![
            "about",
            "generate",
            "--offline",
            "--locked",
            "--fail",
            "--target",
            target,
            "--config",
            "about.toml",
            "--manifest-path",
            manifest,
        ];
        if !features.is_empty() {
            args.extend(["--features", features]);
        }
        args.push(ABOUT_TEMPLATE);
        let section = output_of(Command::new(cargo()).args(&args)).with_context(|| {
            format!(
                "cargo-about on {manifest} (`cargo install --locked cargo-about --features cli`)"
            )
        })?;
        text.push_str(&format!("\n## {product}\n\n{section}"));
    }
    std::fs::write(notices, text)?;
    Ok(())
}

/// The man pages (gzipped, as Debian ships them) and the shell completions, written by the
/// release command line from its own clap definition.
fn generate(built: &Built, generated: &Path) -> anyhow::Result<()> {
    let man = generated.join("man1");
    std::fs::create_dir_all(&man)?;
    run_checked(
        Command::new(&built.cli)
            .arg("generate")
            .arg("man")
            .arg(&man),
    )?;
    for page in files_of(&man)? {
        // -n: no name or time stamp inside, so the same pages give the same bytes.
        run_checked(Command::new("gzip").args(["-9", "-n"]).arg(&page))?;
    }
    for shell in ["bash", "zsh", "fish"] {
        let script = output_of(Command::new(&built.cli).args(["generate", "completion", shell]))?;
        std::fs::write(generated.join(format!("completion.{shell}")), script)?;
    }
    Ok(())
}

/// Lays every file of the release out under `root` as `layout` says.
fn lay_out(
    built: &Built,
    generated: &Path,
    notices: &Path,
    layout: &Layout,
    root: &Path,
) -> anyhow::Result<()> {
    let at = |folder: &str, name: &str| root.join(folder).join(name);
    // The binaries, stripped of their symbol tables (the build keeps them for its backtraces).
    copy_stripped(
        &built.cli,
        &at(layout.bin, "sake-glug"),
        &["--strip-unneeded"],
        0o755,
    )?;
    copy_stripped(
        &built.standalone,
        &at(layout.bin, "sake-glug-standalone"),
        &["--strip-unneeded"],
        0o755,
    )?;
    let soname = soname(&built.shared)?;
    copy_stripped(
        &built.shared,
        &at(&layout.lib, &soname),
        &["--strip-unneeded"],
        0o644,
    )?;
    symlink(&soname, &at(&layout.lib, SHARED_LIBRARY))?;
    copy_stripped(
        &built.static_lib,
        &at(&layout.lib, STATIC_LIBRARY),
        &["--strip-debug"],
        0o644,
    )?;
    write(
        &at(&layout.lib, &format!("pkgconfig/{PACKAGE}.pc")),
        &pkg_config(layout)?,
        0o644,
    )?;
    for header in ["sake_glug.h", "sake_glug.hpp"] {
        copy(
            &Path::new("include").join(header),
            &at(layout.include, header),
            0o644,
        )?;
    }
    copy_stripped(
        &built.clap,
        &at(layout.clap, &format!("{PLUGIN}.clap")),
        &["--strip-unneeded"],
        0o644,
    )?;
    let vst3 = at(layout.vst3, &format!("{PLUGIN}.vst3"));
    for file in files_under(&built.vst3)? {
        let inside = file.strip_prefix(&built.vst3)?;
        copy_stripped(&file, &vst3.join(inside), &["--strip-unneeded"], 0o644)?;
    }

    let share = root.join(layout.share);
    for page in files_of(&generated.join("man1"))? {
        copy(
            &page,
            &share
                .join("man/man1")
                .join(page.file_name().unwrap_or_default()),
            0o644,
        )?;
    }
    copy(
        &generated.join("completion.bash"),
        &share.join(format!("bash-completion/completions/{PACKAGE}")),
        0o644,
    )?;
    copy(
        &generated.join("completion.zsh"),
        &share.join(format!("zsh/vendor-completions/_{PACKAGE}")),
        0o644,
    )?;
    copy(
        &generated.join("completion.fish"),
        &share.join(format!("fish/vendor_completions.d/{PACKAGE}.fish")),
        0o644,
    )?;
    // The data the products read and the faces a program is built with.
    for folder in ["presets", "actuators", "bindings"] {
        copy_tree(Path::new(folder), &share.join(PACKAGE).join(folder))?;
    }
    let doc = root.join(&layout.doc);
    // The folders the docs link to, as in the repository: the guide's study specs and their keys
    // (experiments/), which `experiment --help` names too.
    for folder in ["examples", "docs", "experiments"] {
        copy_tree(Path::new(folder), &doc.join(folder))?;
    }
    for file in ["README.md", "CHANGELOG.md"] {
        copy(Path::new(file), &doc.join(file), 0o644)?;
    }
    if layout.license_file {
        copy(Path::new("LICENSE"), &doc.join("LICENSE"), 0o644)?;
    }
    copy(notices, &doc.join("THIRD-PARTY.md"), 0o644)?;
    Ok(())
}

/// The pkg-config file of the C library: its flags, and for static linking the system libraries
/// that Rust's standard library needs (as rustc reports them for a static library).
fn pkg_config(layout: &Layout) -> anyhow::Result<String> {
    let scratch = std::env::temp_dir().join(format!("sake-glug-dist-{}", std::process::id()));
    std::fs::create_dir_all(&scratch)?;
    let source = scratch.join("empty.rs");
    std::fs::write(&source, "")?;
    let report = Command::new(std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into()))
        .args([
            "--crate-type",
            "staticlib",
            "--print",
            "native-static-libs",
            "-o",
        ])
        .arg(scratch.join("libempty.a"))
        .arg(&source)
        .output()?;
    std::fs::remove_dir_all(&scratch)?;
    let stderr = String::from_utf8_lossy(&report.stderr);
    let private = stderr
        .lines()
        .find_map(|line| line.split("native-static-libs: ").nth(1))
        .context("rustc did not report the native static libraries")?
        .trim()
        .to_owned();
    Ok(format!(
        "prefix={}\n\
         libdir=${{prefix}}/{}\n\
         includedir=${{prefix}}/include\n\
         \n\
         Name: {PACKAGE}\n\
         Description: Sake Glug's C library: the {SUMMARY}, driven live\n\
         Version: {VERSION}\n\
         Libs: -L${{libdir}} -lsake_glug\n\
         Libs.private: {private}\n\
         Cflags: -I${{includedir}}\n",
        layout.pc_prefix, layout.pc_libdir
    ))
}

/// The Debian package from the tree at `root`: its documentation as Debian wants it, the
/// control file with the Depends that dpkg-shlibdeps finds, the checksums, then dpkg-deb.
fn debian_package(root: &Path, out: &Path) -> anyhow::Result<PathBuf> {
    let layout = Layout::debian();
    let doc = root.join(&layout.doc);
    write(&doc.join("copyright"), &debian_copyright()?, 0o644)?;
    let changelog = doc.join("changelog");
    write(&changelog, &debian_changelog()?, 0o644)?;
    run_checked(Command::new("gzip").args(["-9", "-n"]).arg(&changelog))?;

    let depends = shlib_depends(root, &layout)?;
    let installed_kib = files_under(root)?
        .iter()
        .map(|file| std::fs::symlink_metadata(file).map(|m| m.len().div_ceil(1024)))
        .sum::<std::io::Result<u64>>()?;
    let control = format!(
        "Package: {PACKAGE}\n\
         Version: {VERSION}\n\
         Architecture: {DEB_ARCH}\n\
         Maintainer: {MAINTAINER}\n\
         Installed-Size: {installed_kib}\n\
         Depends: {depends}\n\
         Section: sound\n\
         Priority: optional\n\
         Description: {SUMMARY}\n\
         {}",
        debian_description()
    );
    let debian = root.join("DEBIAN");
    write(&debian.join("control"), &control, 0o644)?;
    // The loader's cache learns of the library when dpkg installs or removes it.
    write(
        &debian.join("triggers"),
        "activate-noawait ldconfig\n",
        0o644,
    )?;
    // What a package built against the library depends on (dpkg-shlibdeps reads it): this
    // package, from this version on, for the library of this soname.
    let soname = soname(&root.join(&layout.lib).join(SHARED_LIBRARY))?;
    let (name, abi) = soname
        .split_once(".so.")
        .with_context(|| format!("the soname {soname} has no version"))?;
    write(
        &debian.join("shlibs"),
        &format!("{name} {abi} {PACKAGE} (>= {VERSION})\n"),
        0o644,
    )?;
    let mut sums = String::new();
    for file in files_under(root)? {
        let inside = file.strip_prefix(root)?;
        if inside.starts_with("DEBIAN") || file.is_symlink() {
            continue;
        }
        let sum = output_of(Command::new("md5sum").arg(&file))?;
        let sum = sum
            .split_whitespace()
            .next()
            .context("md5sum printed nothing")?;
        sums.push_str(&format!("{sum}  {}\n", inside.display()));
    }
    write(&debian.join("md5sums"), &sums, 0o644)?;
    let deb = out.join(format!("{PACKAGE}_{VERSION}_{DEB_ARCH}.deb"));
    run_checked(
        Command::new("dpkg-deb")
            .args(["--root-owner-group", "-Zxz", "--build"])
            .arg(root)
            .arg(&deb),
    )?;
    Ok(deb)
}

/// The package's Depends: what dpkg-shlibdeps finds the binaries, the plugins and the library
/// link. It reads debian/control beside the package's tree (debian/<package>), so one is
/// written there.
fn shlib_depends(root: &Path, layout: &Layout) -> anyhow::Result<String> {
    let root = std::path::absolute(root)?;
    let debian = root.parent().context("the package's tree is in debian/")?;
    let control = debian.join("control");
    std::fs::write(
        &control,
        format!("Source: {PACKAGE}\n\nPackage: {PACKAGE}\nArchitecture: {DEB_ARCH}\n"),
    )?;
    let linked: Vec<PathBuf> = files_under(&root)?
        .into_iter()
        .filter(|file| !file.is_symlink() && is_elf_shared_or_executable(file))
        .collect();
    anyhow::ensure!(
        !linked.is_empty(),
        "no binary found to compute Depends from"
    );
    let substvars = output_of(
        Command::new("dpkg-shlibdeps")
            .current_dir(debian.parent().context("debian/ has a parent")?)
            .arg("-O")
            // Our own library, for anything that links it.
            .arg(format!("-l{}", root.join(&layout.lib).display()))
            .args(&linked),
    )?;
    std::fs::remove_file(&control)?;
    substvars
        .lines()
        .find_map(|line| line.strip_prefix("shlibs:Depends="))
        .map(str::to_owned)
        .context("dpkg-shlibdeps gave no shlibs:Depends")
}

/// Whether `file` is an ELF executable or shared object (not a static archive, not text).
fn is_elf_shared_or_executable(file: &Path) -> bool {
    let mut magic = [0u8; 18];
    std::fs::File::open(file)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
        .is_ok()
        && magic[..4] == *b"\x7fELF"
        // e_type: 2 executable, 3 shared object (and position-independent executable).
        && matches!(u16::from_le_bytes([magic[16], magic[17]]), 2 | 3)
}

/// /usr/share/doc/sake-glug/copyright in Debian's machine-readable format: the project's
/// licence, and where the linked crates' licences are.
fn debian_copyright() -> anyhow::Result<String> {
    let license = std::fs::read_to_string("LICENSE")?;
    // The licence's text after its title and copyright line, each line indented, blank ones
    // as " .", as the format wants.
    let copyright = license
        .lines()
        .find(|line| line.starts_with("Copyright"))
        .context("LICENSE has no Copyright line")?
        .trim_start_matches("Copyright (c) ")
        .to_owned();
    let body: String = license
        .lines()
        .skip_while(|line| !line.starts_with("Permission"))
        .map(|line| {
            if line.trim().is_empty() {
                " .\n".to_owned()
            } else {
                format!(" {line}\n")
            }
        })
        .collect();
    Ok(format!(
        "Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/\n\
         Upstream-Name: {PACKAGE}\n\
         Comment: The binaries link Rust crates (and the fonts that epaint_default_fonts\n \
         carries), each under its own licence: see /usr/share/doc/{PACKAGE}/THIRD-PARTY.md,\n \
         written by cargo-about, which names every crate and gives every licence's text.\n\
         \n\
         Files: *\n\
         Copyright: {copyright}\n\
         License: ISC\n\
         \n\
         License: ISC\n{body}"
    ))
}

/// The Debian changelog of this native package: one entry, pointing to CHANGELOG.md.
fn debian_changelog() -> anyhow::Result<String> {
    let date = output_of(Command::new("date").args(["-R", "-u"]))?;
    Ok(format!(
        "{PACKAGE} ({VERSION}) unstable; urgency=medium\n\n  \
         * Release {VERSION}: see /usr/share/doc/{PACKAGE}/CHANGELOG.md.\n\n \
         -- {MAINTAINER}  {}\n",
        date.trim()
    ))
}

fn debian_description() -> String {
    [
        "Sake Glug synthesizes the glug vibration of liquid poured from a Japanese",
        "sake bottle (a tokkuri), for sound designers and haptic designers: a CLAP",
        "and VST3 plugin, a standalone app on JACK or ALSA, the sake-glug offline",
        "renderer (WAV, haptic clips for phones and controllers), and a C library",
        "found by pkg-config as sake-glug. All give the same samples.",
    ]
    .iter()
    .map(|line| format!(" {line}\n"))
    .collect()
}

/// The tarball: the tree under one folder named after it, with install.sh, owned by root with
/// sorted names, so the same files give the same archive.
fn tarball(root: &Path, stem: &str, out: &Path) -> anyhow::Result<PathBuf> {
    write(&root.join("install.sh"), include_str!("install.sh"), 0o755)?;
    let tarball = out.join(format!("{stem}.tar.gz"));
    let parent = root.parent().context("the tree has a parent folder")?;
    run_checked(
        Command::new("tar")
            .args([
                "--sort=name",
                "--owner=0",
                "--group=0",
                "--numeric-owner",
                "-czf",
            ])
            .arg(std::path::absolute(&tarball)?)
            .arg("-C")
            .arg(parent)
            .arg(stem),
    )?;
    Ok(tarball)
}

/// The soname the C library was linked with (crates/capi/build.rs), read from its ELF header.
pub fn soname(library: &Path) -> anyhow::Result<String> {
    let dynamic = output_of(Command::new("objdump").arg("-p").arg(library))?;
    dynamic
        .lines()
        .find_map(|line| line.trim().strip_prefix("SONAME"))
        .map(|name| name.trim().to_owned())
        .with_context(|| format!("{} has no soname", library.display()))
}

fn copy_stripped(from: &Path, to: &Path, how: &[&str], mode: u32) -> anyhow::Result<()> {
    copy(from, to, mode)?;
    run_checked(Command::new("strip").args(how).arg(to))
}

fn copy(from: &Path, to: &Path, mode: u32) -> anyhow::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::copy(from, to)
        .with_context(|| format!("copying {} to {}", from.display(), to.display()))?;
    std::fs::set_permissions(to, std::fs::Permissions::from_mode(mode))?;
    Ok(())
}

fn write(to: &Path, text: &str, mode: u32) -> anyhow::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::write(to, text)?;
    std::fs::set_permissions(to, std::fs::Permissions::from_mode(mode))?;
    Ok(())
}

fn symlink(target: &str, link: &Path) -> anyhow::Result<()> {
    if let Some(parent) = link.parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::os::unix::fs::symlink(target, link)?;
    Ok(())
}

/// Copies the files of the repository's folder `from` (those git tracks, none of a build's
/// leftovers) under `to`.
pub fn copy_tree(from: &Path, to: &Path) -> anyhow::Result<()> {
    let listed = output_of(Command::new("git").args(["ls-files", "-z", "--"]).arg(from))?;
    for file in listed.split('\0').filter(|name| !name.is_empty()) {
        let file = Path::new(file);
        copy(file, &to.join(file.strip_prefix(from)?), 0o644)?;
    }
    Ok(())
}

/// Empties `folder` (made if missing): a folder made afresh each run, so that nothing an earlier
/// run left (a failed one's half tree) joins this one's.
pub fn fresh_folder(folder: &Path) -> anyhow::Result<()> {
    if folder.exists() {
        std::fs::remove_dir_all(folder)
            .with_context(|| format!("emptying {}", folder.display()))?;
    }
    std::fs::create_dir_all(folder).with_context(|| format!("making {}", folder.display()))
}

/// The files (and symbolic links) directly in `folder`, sorted.
fn files_of(folder: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)?
        .map(|entry| entry.map(|entry| entry.path()))
        .collect::<std::io::Result<_>>()?;
    files.retain(|path| !path.is_dir() || path.is_symlink());
    files.sort();
    Ok(files)
}

/// Every file (and symbolic link) under `folder`, at any depth, sorted.
pub fn files_under(folder: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut folders = vec![folder.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder)? {
            let path = entry?.path();
            if path.is_dir() && !path.is_symlink() {
                folders.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

pub fn run_checked(command: &mut Command) -> anyhow::Result<()> {
    let status = command
        .status()
        .with_context(|| format!("running {command:?}"))?;
    anyhow::ensure!(status.success(), "{command:?} failed ({status})");
    Ok(())
}

/// The command's stdout; its stderr is shown only if it fails.
pub fn output_of(command: &mut Command) -> anyhow::Result<String> {
    let out = command
        .output()
        .with_context(|| format!("running {command:?}"))?;
    anyhow::ensure!(
        out.status.success(),
        "{command:?} failed ({}):\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    Ok(String::from_utf8(out.stdout)?)
}

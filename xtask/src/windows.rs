//! The Windows release (x86-64), cross-built on Linux with Debian's MinGW-w64 and packed here:
//! an installer written by NSIS's `makensis` and a portable zip, both in target/dist/, from one
//! tree laid out once. The version is the workspace's, as for every other product.
//!
//! The installer puts the VST3 bundle in `%CommonProgramFiles%\VST3` and the CLAP plugin in
//! `%CommonProgramFiles%\CLAP`, where Windows hosts look without being told, and the programs,
//! the C library and the data in `%ProgramFiles%\Sake Glug`; it adds that folder's `bin` to the
//! system PATH only when asked (its Components page, or `/PATH` on the command line). Its
//! uninstaller deletes the files the installer wrote, listed one by one in the script from the
//! same tree, and only the folders that are then empty. `/S` runs either silently.
//!
//! Beside them, the Python package as a `win_amd64` wheel (abi3, CPython 3.8 on), built by maturin
//! as the Linux wheel is: PyO3 links `python3.dll` by raw-dylib, so no Windows Python is needed to
//! build it (none can be had here to run it either; docs/testing.md).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;

use crate::dist::VERSION;

/// The Rust target the Windows products are built for.
pub const TARGET: &str = "x86_64-pc-windows-gnu";
/// The plugin's bundles, the install folder and the product's name in Windows' list of programs.
const PLUGIN: &str = "Sake Glug";
/// The artefacts' stem: `sake-glug-<version>-windows-x86_64.zip`, `…-setup.exe`.
const ARCH: &str = "windows-x86_64";
const PUBLISHER: &str = "The Sake Glug authors";
/// The tree's folders that go under `%CommonProgramFiles%` rather than the install folder.
const PLUGIN_FOLDERS: [&str; 2] = ["CLAP", "VST3"];
/// What the cross-build and the packing run, and the Debian package of each.
const TOOLS: [(&str, &str); 5] = [
    ("x86_64-w64-mingw32-gcc", "gcc-mingw-w64-x86-64"),
    ("x86_64-w64-mingw32-strip", "binutils-mingw-w64-x86-64"),
    // rustc makes the import library of PyO3's raw-dylib link to python3.dll with it.
    ("x86_64-w64-mingw32-dlltool", "binutils-mingw-w64-x86-64"),
    ("makensis", "nsis"),
    ("zip", "zip"),
];

/// Fails at once, in one line naming what to install, if the Windows products cannot be built
/// and packed here.
pub fn require_tools(command: &str) -> anyhow::Result<()> {
    let missing: Vec<&str> = TOOLS
        .iter()
        .filter(|(tool, _)| Command::new(tool).arg("--version").output().is_err())
        .map(|(_, package)| *package)
        .collect();
    let sysroot = crate::output("rustc", &["--print", "sysroot"])?;
    let target_installed = Path::new(sysroot.trim())
        .join("lib/rustlib")
        .join(TARGET)
        .is_dir();
    let mut needs = Vec::new();
    if !missing.is_empty() {
        needs.push(format!("sudo apt-get install {}", missing.join(" ")));
    }
    if !target_installed {
        needs.push(format!("rustup target add {TARGET}"));
    }
    anyhow::ensure!(
        needs.is_empty(),
        "{command} builds the Windows release: {}",
        needs.join(" and ")
    );
    Ok(())
}

/// The cargo profile the shipped Windows release is built with.
pub const RELEASE_PROFILE: &str = "release";
/// The profile of the Windows build `cargo xtask test` runs under Wine: the release's code, built
/// faster (Cargo.toml says how).
pub const TEST_PROFILE: &str = "windows-test";

/// Where cargo leaves the Windows builds of `profile`.
fn profile_dir(profile: &str) -> PathBuf {
    crate::target_dir().join(TARGET).join(profile)
}

/// Where the Windows bundles of `profile` are laid out (the Linux ones are in target/bundled).
fn bundled_dir(profile: &str) -> PathBuf {
    profile_dir(profile).join("bundled")
}

/// Where the installer and zip of `profile` are written: target/dist for the release (beside the
/// Linux release), a folder of their own for any other profile, so that no test build is taken
/// for the release.
pub fn dist_dir(profile: &str) -> PathBuf {
    if profile == RELEASE_PROFILE {
        crate::target_dir().join("dist")
    } else {
        crate::target_dir().join(format!("dist-{profile}"))
    }
}

fn cargo_build(profile: &str, what: &[&str]) -> anyhow::Result<()> {
    let mut args = vec!["build", "--profile", profile, "--target", TARGET];
    args.extend(what);
    crate::cargo(&args)
}

/// The packages of the Windows products, each run of their build names them all: cargo unifies
/// the features of their shared crates over the packages a run names, so both runs build those
/// crates alike and the second compiles again only what `standalone` changes. (maturin's run for
/// the wheel names the Python package alone, and compiles the crates it shares with these again
/// with its own features.)
const PACKAGES: [&str; 6] = [
    "--package",
    "sake-glug-plugin",
    "--package",
    "sake-glug",
    "--package",
    "sake-glug-c",
];

/// Builds the Windows products but the wheel with `profile`, in two cargo runs. The first makes
/// the plugin with its editor, the command line with `ogg` and the C library; the plugin's DLL is
/// laid out as its CLAP and VST3 bundles at once. The second makes the standalone app, with the
/// plugin's `standalone` feature, and replaces the DLL: cargo unifies a package's features within
/// a run, so one run would give the plugin nice-plug's tracing-subscriber, which installs a
/// global logger and panic hook in every host that loads it. Says how long each run took (on
/// CI's two cores the second costs minutes: docs/testing.md).
pub fn build(profile: &str) -> anyhow::Result<()> {
    require_tools("the Windows build")?;
    let started = std::time::Instant::now();
    cargo_build(
        profile,
        &[&PACKAGES[..], &["--lib", "--bin", "sake-glug"]].concat(),
    )?;
    bundle_plugin(
        &profile_dir(profile).join("sake_glug_plugin.dll"),
        &bundled_dir(profile),
    )?;
    let first = started.elapsed().as_secs_f64();
    cargo_build(
        profile,
        &[
            &PACKAGES[..],
            &[
                "--bin",
                "sake-glug-standalone",
                "--features",
                "sake-glug-plugin/standalone",
            ],
        ]
        .concat(),
    )?;
    let total = started.elapsed().as_secs_f64();
    println!(
        "windows: built with the {profile} profile in {total:.0} s \
         (the app's run {:.0} s of it)",
        total - first
    );
    Ok(())
}

/// Where maturin writes the Windows wheel of `profile`: a folder of its own, not target/wheels,
/// where `cargo xtask dist` takes the newest wheel for the Linux release.
pub fn wheel_dir(profile: &str) -> PathBuf {
    profile_dir(profile).join("wheels")
}

/// The win_amd64 wheel's file name ends so (abi3, so one wheel for every CPython from 3.8 on).
const WHEEL_TAG: &str = "-cp38-abi3-win_amd64.whl";

/// The plugin's DLL as Windows hosts want it: `Sake Glug.clap` (CLAP has no bundle on Windows)
/// and `Sake Glug.vst3/Contents/x86_64-win/Sake Glug.vst3` (Steinberg's bundle layout), as
/// nice-plug's bundler lays them out for this target. That bundler writes into target/bundled,
/// where it would replace the Linux bundles of the same names, so the two copies are made here.
fn bundle_plugin(library: &Path, bundled: &Path) -> anyhow::Result<()> {
    if bundled.exists() {
        std::fs::remove_dir_all(bundled)?;
    }
    copy(library, &bundled.join(format!("{PLUGIN}.clap")))?;
    copy(
        library,
        &bundled.join(format!("{PLUGIN}.vst3/Contents/x86_64-win/{PLUGIN}.vst3")),
    )
}

/// What the Windows build made.
pub struct Built {
    cli: PathBuf,
    standalone: PathBuf,
    clap: PathBuf,
    vst3: PathBuf,
    library: PathBuf,
    import_library: PathBuf,
    wheel: PathBuf,
}

impl Built {
    /// What `build(profile)` and maturin made.
    pub fn here(profile: &str) -> anyhow::Result<Self> {
        let release = profile_dir(profile);
        let bundled = bundled_dir(profile);
        let wheel = wheel_dir(profile).join(format!("sake_glug-{VERSION}{WHEEL_TAG}"));
        let built = Self {
            cli: release.join("sake-glug.exe"),
            standalone: release.join("sake-glug-standalone.exe"),
            clap: bundled.join(format!("{PLUGIN}.clap")),
            vst3: bundled.join(format!("{PLUGIN}.vst3")),
            library: release.join("sake_glug.dll"),
            import_library: release.join("libsake_glug.dll.a"),
            wheel,
        };
        for path in [
            &built.cli,
            &built.standalone,
            &built.clap,
            &built.vst3,
            &built.library,
            &built.import_library,
            &built.wheel,
        ] {
            anyhow::ensure!(
                path.exists(),
                "{} is missing: the Windows build did not make it",
                path.display()
            );
        }
        Ok(built)
    }
}

/// The Windows products, for their THIRD-PARTY.md: the command line has no `audio` here (its
/// study and measurement play through JACK and ALSA).
const PRODUCTS: [crate::dist::Product; 4] = [
    ("The command line, `sake-glug.exe`", "Cargo.toml", "ogg"),
    (
        "The plugin (CLAP, VST3) and the standalone app, `sake-glug-standalone.exe`",
        "crates/plugin/Cargo.toml",
        "editor,standalone",
    ),
    (
        "The C library, `sake_glug.dll`",
        "crates/capi/Cargo.toml",
        "",
    ),
    ("The Python package, `sake_glug`", "python/Cargo.toml", ""),
];

/// Writes the Windows installer and zip into `out` (beside the Linux release), and copies the
/// wheel there beside them. Returns their paths.
pub fn dist(built: &Built, out: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let stem = format!("sake-glug-{VERSION}-{ARCH}");
    let work = out.join("windows-work");
    let root = work.join(&stem);
    let notices = work.join("THIRD-PARTY.md");
    // A tree left by a packing that failed half way would add its files to this one.
    crate::dist::fresh_folder(&work)?;
    crate::dist::third_party(&notices, TARGET, &PRODUCTS)?;
    lay_out(built, &notices, &root)?;
    let zip = out.join(format!("{stem}.zip"));
    // zip adds to an archive that exists, keeping the files an earlier tree had and this one
    // has not.
    if zip.exists() {
        std::fs::remove_file(&zip)?;
    }
    crate::dist::run_checked(
        Command::new("zip")
            .args(["-q", "-X", "-r", "-9"])
            .arg(std::path::absolute(&zip)?)
            .arg(&stem)
            .current_dir(&work),
    )?;
    let installer = out.join(format!("{stem}-setup.exe"));
    let script = work.join("installer.nsi");
    std::fs::write(&script, nsis_script(&root, &installer)?)?;
    crate::dist::run_checked(
        Command::new("makensis")
            .args(["-V2", "-INPUTCHARSET", "UTF8"])
            .arg(&script),
    )?;
    std::fs::remove_dir_all(&work)?;
    let wheel = out.join(built.wheel.file_name().context("the wheel has a name")?);
    copy(&built.wheel, &wheel)?;
    Ok(vec![installer, zip, wheel])
}

/// The one tree both artefacts hold: the install folder's contents at its root, the plugins in
/// its `CLAP` and `VST3` folders (the zip's user copies those to `%CommonProgramFiles%`).
fn lay_out(built: &Built, notices: &Path, root: &Path) -> anyhow::Result<()> {
    let bin = root.join("bin");
    copy_stripped(&built.cli, &bin.join("sake-glug.exe"))?;
    copy_stripped(&built.standalone, &bin.join("sake-glug-standalone.exe"))?;
    // The C library's DLL beside the programs: on the PATH with them, and found there by a
    // program that has it beside itself or on its PATH.
    copy_stripped(&built.library, &bin.join("sake_glug.dll"))?;
    copy(&built.import_library, &root.join("lib/libsake_glug.dll.a"))?;
    for header in ["sake_glug.h", "sake_glug.hpp"] {
        copy(
            &Path::new("include").join(header),
            &root.join("include").join(header),
        )?;
    }
    copy_stripped(&built.clap, &root.join(format!("CLAP/{PLUGIN}.clap")))?;
    for file in crate::dist::files_under(&built.vst3)? {
        let inside = file.strip_prefix(&built.vst3)?;
        copy_stripped(
            &file,
            &root.join(format!("VST3/{PLUGIN}.vst3")).join(inside),
        )?;
    }
    for folder in ["presets", "actuators", "bindings", "examples", "docs"] {
        crate::dist::copy_tree(Path::new(folder), &root.join(folder))?;
    }
    for file in ["README.md", "CHANGELOG.md", "LICENSE"] {
        copy(Path::new(file), &root.join(file))?;
    }
    copy(notices, &root.join("THIRD-PARTY.md"))
}

/// Where an entry of the tree is installed: the plugin folders under `%CommonProgramFiles%`
/// (64-bit), everything else under the install folder.
fn destination(inside: &Path) -> String {
    let first = inside
        .components()
        .next()
        .map(|part| part.as_os_str().to_string_lossy().into_owned())
        .unwrap_or_default();
    let windows_path = |path: &Path| path.to_string_lossy().replace('/', "\\");
    if PLUGIN_FOLDERS.contains(&first.as_str()) {
        format!("$COMMONFILES64\\{}", windows_path(inside))
    } else {
        format!("$INSTDIR\\{}", windows_path(inside))
    }
}

/// A string as an NSIS script quotes it: `$` (its variables) and `"` escaped.
fn quoted(text: &str) -> String {
    format!("\"{}\"", text.replace('$', "$$").replace('"', "$\\\""))
}

/// The installer's NSIS script: every file of the tree installed where `destination` says and
/// deleted again by the uninstaller, then each folder that holds none (deepest first).
fn nsis_script(root: &Path, installer: &Path) -> anyhow::Result<String> {
    let root = std::path::absolute(root)?;
    let files = crate::dist::files_under(&root)?;
    let mut install = String::new();
    let mut uninstall = String::new();
    let mut folders = std::collections::BTreeSet::new();
    let mut kib = 0;
    let mut current = String::new();
    for file in &files {
        let inside = file.strip_prefix(&root)?;
        let installed = destination(inside);
        let folder = installed
            .rsplit_once('\\')
            .map(|(folder, _)| folder.to_owned())
            .context("an installed file is in a folder")?;
        if folder != current {
            // NSIS takes `$INSTDIR` and `$COMMONFILES64` as variables: only the file names of
            // the tree are quoted with their `$` escaped.
            install.push_str(&format!("  SetOutPath \"{folder}\"\n"));
            current = folder.clone();
        }
        install.push_str(&format!("  File {}\n", quoted(&file.to_string_lossy())));
        uninstall.push_str(&format!("  Delete \"{installed}\"\n"));
        let mut parent = Path::new(inside).parent();
        while let Some(path) = parent.filter(|path| !path.as_os_str().is_empty()) {
            folders.insert(destination(path));
            parent = path.parent();
        }
        kib += file.metadata()?.len().div_ceil(1024);
    }
    // Deepest first; RMDir without /r removes a folder only when it is empty, so a VST3 or CLAP
    // folder that holds other plugins stays.
    let mut folders: Vec<String> = folders.into_iter().collect();
    folders.sort_by_key(|folder| std::cmp::Reverse(folder.matches('\\').count()));
    for folder in folders {
        uninstall.push_str(&format!("  RMDir \"{folder}\"\n"));
    }
    let license = std::path::absolute("LICENSE")?;
    let numeric_version = format!("{VERSION}.0");
    Ok(format!(
        r#"; Written by `cargo xtask dist` (xtask/src/windows.rs); not kept in the repository.
Unicode true
Target amd64-unicode
SetCompressor /SOLID lzma
!include "LogicLib.nsh"
!include "FileFunc.nsh"
!include "WordFunc.nsh"
!include "WinMessages.nsh"
!include "Sections.nsh"

!define UNINSTALL_KEY "Software\Microsoft\Windows\CurrentVersion\Uninstall\{PLUGIN}"
!define ENVIRONMENT_KEY "SYSTEM\CurrentControlSet\Control\Session Manager\Environment"

Name "{PLUGIN} {VERSION}"
OutFile {outfile}
InstallDir "$PROGRAMFILES64\{PLUGIN}"
RequestExecutionLevel admin
ShowInstDetails show
ShowUninstDetails show
LicenseData {license}
VIProductVersion "{numeric_version}"
VIAddVersionKey "ProductName" "{PLUGIN}"
VIAddVersionKey "ProductVersion" "{VERSION}"
VIAddVersionKey "FileVersion" "{VERSION}"
VIAddVersionKey "CompanyName" "{PUBLISHER}"
VIAddVersionKey "LegalCopyright" "ISC licence"
VIAddVersionKey "FileDescription" "{PLUGIN} {VERSION} installer"

Page license
Page components
Page directory
Page instfiles
UninstPage uninstConfirm
UninstPage instfiles

Section "{PLUGIN}: the VST3 and CLAP plugins, the app, sake-glug, the C library" SectionMain
  SectionIn RO
{install}  WriteUninstaller "$INSTDIR\uninstall.exe"
  WriteRegStr HKLM "${{UNINSTALL_KEY}}" "DisplayName" "{PLUGIN}"
  WriteRegStr HKLM "${{UNINSTALL_KEY}}" "DisplayVersion" "{VERSION}"
  WriteRegStr HKLM "${{UNINSTALL_KEY}}" "Publisher" "{PUBLISHER}"
  WriteRegStr HKLM "${{UNINSTALL_KEY}}" "InstallLocation" "$INSTDIR"
  WriteRegStr HKLM "${{UNINSTALL_KEY}}" "UninstallString" '"$INSTDIR\uninstall.exe"'
  WriteRegStr HKLM "${{UNINSTALL_KEY}}" "QuietUninstallString" '"$INSTDIR\uninstall.exe" /S'
  WriteRegDWORD HKLM "${{UNINSTALL_KEY}}" "NoModify" 1
  WriteRegDWORD HKLM "${{UNINSTALL_KEY}}" "NoRepair" 1
  WriteRegDWORD HKLM "${{UNINSTALL_KEY}}" "EstimatedSize" {kib}
SectionEnd

; Off unless asked: the Components page, or /PATH on the command line (with /S too).
Section /o "Add sake-glug to the PATH" SectionPath
  ReadRegStr $0 HKLM "${{ENVIRONMENT_KEY}}" "Path"
  ${{If}} $0 == ""
    StrCpy $1 "$INSTDIR\bin"
  ${{Else}}
    StrCpy $1 "$0;$INSTDIR\bin"
  ${{EndIf}}
  StrLen $2 $1
  ; NSIS holds at most NSIS_MAX_STRLEN characters: a PATH that long would come back cut, and
  ; writing it would lose the rest, so it is left alone.
  ${{If}} $2 >= ${{NSIS_MAX_STRLEN}}
    MessageBox MB_OK|MB_ICONEXCLAMATION "The PATH is too long to extend safely: add $INSTDIR\bin to it yourself." /SD IDOK
  ${{Else}}
    WriteRegExpandStr HKLM "${{ENVIRONMENT_KEY}}" "Path" $1
    WriteRegDWORD HKLM "${{UNINSTALL_KEY}}" "AddedToPath" 1
    SendMessage ${{HWND_BROADCAST}} ${{WM_SETTINGCHANGE}} 0 "STR:Environment" /TIMEOUT=5000
  ${{EndIf}}
SectionEnd

Function .onInit
  SetRegView 64
  SetShellVarContext all
  ${{GetParameters}} $0
  ClearErrors
  ${{GetOptions}} $0 "/PATH" $1
  ${{IfNot}} ${{Errors}}
    !insertmacro SelectSection ${{SectionPath}}
  ${{EndIf}}
FunctionEnd

Function un.onInit
  SetRegView 64
  SetShellVarContext all
FunctionEnd

Section "Uninstall"
  ReadRegDWORD $0 HKLM "${{UNINSTALL_KEY}}" "AddedToPath"
  ${{If}} $0 == 1
    ReadRegStr $1 HKLM "${{ENVIRONMENT_KEY}}" "Path"
    ${{If}} $1 == "$INSTDIR\bin"
      StrCpy $2 ""
    ${{Else}}
      ${{un.WordReplace}} $1 ";$INSTDIR\bin" "" "+" $2
    ${{EndIf}}
    WriteRegExpandStr HKLM "${{ENVIRONMENT_KEY}}" "Path" $2
    SendMessage ${{HWND_BROADCAST}} ${{WM_SETTINGCHANGE}} 0 "STR:Environment" /TIMEOUT=5000
  ${{EndIf}}
{uninstall}  Delete "$INSTDIR\uninstall.exe"
  RMDir "$INSTDIR"
  DeleteRegKey HKLM "${{UNINSTALL_KEY}}"
SectionEnd
"#,
        outfile = quoted(&std::path::absolute(installer)?.to_string_lossy()),
        license = quoted(&license.to_string_lossy()),
    ))
}

fn copy(from: &Path, to: &Path) -> anyhow::Result<()> {
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::copy(from, to)
        .with_context(|| format!("copying {} to {}", from.display(), to.display()))?;
    Ok(())
}

/// A program or DLL without its symbol tables (the build keeps them for its backtraces).
fn copy_stripped(from: &Path, to: &Path) -> anyhow::Result<()> {
    copy(from, to)?;
    crate::dist::run_checked(
        Command::new("x86_64-w64-mingw32-strip")
            .arg("--strip-unneeded")
            .arg(to),
    )
}

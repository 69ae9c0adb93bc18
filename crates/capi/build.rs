//! The shared library's soname, `libsake_glug.so.<ABI>`: a program linked against it asks for
//! the interface it was built with, and a library of another interface can be installed beside.
//! The ABI version is read from crates/capi/src/types.rs, where it is declared for the header.

fn main() {
    println!("cargo:rerun-if-changed=src/types.rs");
    let types =
        std::fs::read_to_string("src/types.rs").expect("crates/capi/src/types.rs is readable");
    let abi = types
        .lines()
        .find_map(|line| line.strip_prefix("pub const SAKE_GLUG_ABI_VERSION: u32 = "))
        .and_then(|rest| rest.strip_suffix(';'))
        .expect("src/types.rs declares `pub const SAKE_GLUG_ABI_VERSION: u32 = N;`");
    let target_os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target_os == "linux" {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libsake_glug.so.{abi}");
    }
}

//! Every file the product writes (renders, clips, plots, models, logs) is first written as a temporary
//! file beside its target and renamed over it once complete, so none is ever left half written.

/// A temporary file as the crate writes one: temporary files are private by default, but the
/// finished file should get the permissions any new file gets (0o666 less the umask), as if it
/// had been written in place.
pub fn temp_file_builder() -> tempfile::Builder<'static, 'static> {
    #[cfg_attr(
        not(unix),
        expect(unused_mut, reason = "Windows files have no mode bits to set")
    )]
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder
}

//! `include/lucent.h` is what cbindgen generates from the crate today, byte for byte.
//! `LUCENT_BLESS=1 cargo test -p lucent-ffi --features header-check --test it header::` regenerates it.

use std::path::Path;

#[test]
fn header_is_current() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap();
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_crate(crate_dir)
        .generate()
        .expect("cbindgen parses the crate");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let path = crate_dir.join("include/lucent.h");
    if std::env::var_os("LUCENT_BLESS").is_some_and(|v| !v.is_empty() && v != "0") {
        std::fs::write(&path, &generated).unwrap();
        return;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is stale: regenerate it with LUCENT_BLESS=1 cargo test -p lucent-ffi --features header-check --test it header::",
        path.display()
    );
}

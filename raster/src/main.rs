//! `lucent`: render translucent OBJ scenes from the command line.
fn main() {
    std::process::exit(lucent_raster::cli::main());
}

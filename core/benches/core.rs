//! Core micro-benchmarks (divan).
fn main() {
    divan::main();
}

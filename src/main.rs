//! The `polhode` binary: see [`polhode::cli`].

fn main() {
    std::process::exit(polhode::cli::main());
}

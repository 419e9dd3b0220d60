//! Project automation (`cargo xtask regress`, `cargo xtask bench`).
fn main() {
    println!("xtask: not yet wired");
}

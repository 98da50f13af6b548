fn main() {
    println!("curvetet {}", env!("CARGO_PKG_VERSION"));
}

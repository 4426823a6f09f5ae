//! Lex + parse + interpret throughput on a dense 3D-surfacing program.
fn main() {}

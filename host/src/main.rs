fn main() { println!("{}", env!("treelet_shader.spv")); }

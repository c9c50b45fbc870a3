//! Frequencies of a payload-link scene with the kind of each mode (the CLI's `modes` prints
//! frequencies only). Run: cargo run --release -p fdm --example payload_link_modes --
//! single-link-3d 21 8
use data::load_scene;
use fdm::payload_link::PayloadLinkModel;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: payload_link_modes <scene> [stations] [count]";
    let Some(name) = args.get(1) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let parse = |i: usize, default: usize| match args.get(i) {
        None => default,
        Some(s) => s.parse().unwrap_or_else(|_| {
            eprintln!("{usage}: `{s}` is not a count");
            std::process::exit(2)
        }),
    };
    let (stations, count) = (parse(2, 21), parse(3, 6));
    let result = load_scene(name)
        .map_err(|e| e.to_string())
        .and_then(|s| {
            PayloadLinkModel::from_payload_link(&s, s.payload_link().unwrap(), Some(stations))
                .map_err(|e| e.to_string())
        })
        .and_then(|m| m.spectrum().map_err(|e| e.to_string()));
    match result {
        Ok(sp) => {
            for j in 0..count.min(sp.omega.len()) {
                let f = sp.omega[j] / (2.0 * std::f64::consts::PI);
                println!("{:>3}  {f:.9e} Hz  {}", j + 1, sp.kinds[j]);
            }
        }
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    }
}

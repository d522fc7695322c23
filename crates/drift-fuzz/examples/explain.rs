//! Prints what the readers say about one input file (a corpus entry or a finding):
//! `cargo run -p drift-fuzz --example explain -- <target> <file>`.

use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(target), Some(file)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: explain <blob|recording|csv|corrector> <file>");
        std::process::exit(2);
    };
    let bytes = match std::fs::read(file) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("{file}: {e}");
            std::process::exit(1);
        }
    };
    match target.as_str() {
        "recording" => match drift_recording::read_recording_bytes(Path::new(file), &bytes) {
            Ok(r) => println!("accepted: {} segments", r.segments.len()),
            Err(e) => println!("refused: {e}"),
        },
        "csv" => {
            let text = bytes.get(1..).unwrap_or_default();
            match drift_recording::read_csv_bytes(Path::new(file), text, &Default::default()) {
                Ok(r) => println!("accepted (default options): {} segments", r.segments.len()),
                Err(e) => println!("refused (default options): {e}"),
            }
        }
        "blob" => {
            let mut image = bytes.get(1..).unwrap_or_default().to_vec();
            drift_fuzz::blob::prepare(bytes.first().copied().unwrap_or(0), &mut image);
            match drift_core::blob::decode::<drift_core::ModifiedTables>(&image) {
                Ok(_) => println!("accepted as modified tables"),
                Err(e) => println!("modified: {e}"),
            }
            match drift_core::blob::decode::<drift_core::PolynomialTables>(&image) {
                Ok(_) => println!("accepted as polynomial tables"),
                Err(e) => println!("polynomial: {e}"),
            }
        }
        _ => {
            drift_fuzz::TARGETS
                .iter()
                .filter(|(t, _)| t == target)
                .for_each(|(_, run)| run(&bytes));
            println!("passes its target");
        }
    }
}

//! A run finds what is planted in targets made to have it: a panic, messages that are not one
//! line naming the file. (Its own test binary: a run's panic hook is process-wide.)

use input_fuzz::{Format, Target};

#[test]
fn a_run_counts_panics_and_bad_messages() {
    let targets = vec![
        Target {
            name: "panics",
            extension: "bin",
            format: Format::Json,
            seeds: vec![b"{}".to_vec()],
            run: Box::new(|bytes, _| if bytes.len() == 1 { panic!("planted") } else { Ok(()) }),
        },
        Target {
            name: "bad-message",
            extension: "bin",
            format: Format::Json,
            seeds: vec![b"[1,2]".to_vec()],
            run: Box::new(|bytes, path| match bytes.len() {
                0 => Err("two\nlines".to_string()),
                1 => Err("no file named".to_string()),
                _ => Err(format!("{}: a reason on one line", path.display())),
            }),
        },
    ];
    let report = input_fuzz::run(&targets, 400, 1, None, &mut |_| {});
    assert_eq!(report.cases, 400);
    assert!(report.panics >= 1, "{report:?}");
    assert!(report.bad_messages >= 2, "{report:?}");
    assert!(!report.is_clean());
    assert!(report.findings.iter().any(|f| f.what.contains("planted") && f.input.len() == 1), "{:?}", report.findings);
    assert!(report.summary().starts_with("fuzz: 400 cases, "), "{}", report.summary());
    assert!(input_fuzz::is_good_message(
        "fuzz-case-3.exr: not an OpenEXR (.exr) or Radiance (.hdr) image",
        "fuzz-case-3.exr"
    ));
    assert!(!input_fuzz::is_good_message("fuzz-case-3.exr:", "fuzz-case-3.exr"));
}

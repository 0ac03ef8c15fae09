//! The XDMF sidecar of a run: a complete document after the run that lists
//! every step of the HDF5 file, in order, read by a real XML parser.
mod common;
use common::*;
use contactlink::output::layout;

#[test]
fn sidecar_of_a_many_step_run_parses_and_lists_every_step() {
    let dir = scratch("xdmf-steps");
    let out = dir.join("out.h5");
    let steps = 40;
    let count = format!("steps.count={steps}");
    let o = mpirun(
        2,
        &[
            "run",
            "uniaxial-stretch",
            "-q",
            "--set",
            &count,
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let listed = contactlink::output::list_steps(&out).expect("steps of the result file");
    assert_eq!(listed.len(), steps);
    // Python's own XML parser (python3 is installed with matplotlib by
    // scripts/install-deps.sh): grid names and times in order.
    let script = "import sys, xml.etree.ElementTree as ET\n\
        root = ET.parse(sys.argv[1]).getroot()\n\
        grids = root.findall('./Domain/Grid/Grid')\n\
        print(len(grids))\n\
        for g in grids: print(g.get('Name'), g.find('Time').get('Value'), len(g.findall('Attribute')))\n";
    let parsed = std::process::Command::new("/usr/bin/python3")
        .args(["-c", script, out.with_extension("xmf").to_str().unwrap()])
        .output()
        .expect("run python3");
    let report = String::from_utf8_lossy(&parsed.stdout);
    assert!(
        parsed.status.success(),
        "the sidecar does not parse: {}",
        String::from_utf8_lossy(&parsed.stderr)
    );
    let mut lines = report.lines();
    assert_eq!(lines.next(), Some(steps.to_string().as_str()), "{report}");
    for (i, line) in lines.enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(
            words[0],
            format!("step_{}", layout::step_group_name(i + 1)),
            "{report}"
        );
        let time: f64 = words[1].parse().unwrap();
        assert!(
            (time - (i + 1) as f64 / steps as f64).abs() < 1e-12,
            "{line}"
        );
        assert!(words[2].parse::<usize>().unwrap() >= 4, "{line}");
    }
}

//! The JSON report of an assessment: the library's (`voussoir::report::AssessmentReport`,
//! shared with `python -m voussoir --assess`), its settings naming the supports and the
//! input files as the command line gave them.

use std::path::PathBuf;

use voussoir::report::AssessmentReport;

use super::run::Assessed;
use crate::args::Options;

/// The report of `a`.
pub fn build(o: &Options, a: &Assessed) -> AssessmentReport {
    let mut report = AssessmentReport::new(
        &a.model.read,
        &a.envelope,
        &a.settings,
        &a.result,
        a.thickness,
    );
    let path = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
    let settings = &mut report.settings;
    settings.read.supports = a.model.supports.clone();
    settings.intrados = path(&o.assess.intrados);
    settings.extrados = path(&o.assess.extrados);
    settings.load_pattern = path(&o.assess.load_pattern);
    report
}

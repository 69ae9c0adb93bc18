//! An automation lane as a scene gives it: inline points or a CSV file read into points, every
//! value in its range and every point time in order.

use std::path::Path;

use super::{InputFile, SceneError};
use crate::automation::{Automation, CsvLaneRef, LaneSpec};
use sake_glug_device::axis::Axis;
use sake_glug_device::csv_lane::{read_csv_lane, CsvLaneSpec, MAX_CSV_LANE_BYTES};
use sake_glug_engine::Range;
use sake_glug_io::read;

/// A lane as the scene wrote it, with a CSV take read into points (relative to `folder`) and
/// its file added to `inputs`.
pub(super) fn resolve(
    key: &'static str,
    spec: Option<LaneSpec>,
    folder: &Path,
    inputs: &mut Vec<InputFile>,
) -> Result<Option<Automation>, SceneError> {
    let reference = match spec {
        None => return Ok(None),
        Some(LaneSpec::Inline(automation)) => return Ok(Some(automation)),
        Some(LaneSpec::Csv(reference)) => reference,
    };
    let form = |message: &str| SceneError::CsvForm {
        key,
        message: message.to_string(),
    };
    let CsvLaneRef {
        csv,
        column,
        accel,
        axis,
    } = reference;
    let spec = match (column, accel) {
        (Some(column), None) if axis.is_none() => CsvLaneSpec::Column(column),
        (None, Some(columns)) if key == "tilt_deg" => {
            let axis: Axis = axis.as_deref().unwrap_or("+z").parse().map_err(
                |error: sake_glug_device::axis::AxisParseError| form(&error.to_string()),
            )?;
            CsvLaneSpec::Gravity { columns, axis }
        }
        (None, Some(_)) => return Err(form("`accel` gives a tilt: only tilt_deg takes it")),
        (Some(_), None) => return Err(form("`axis` goes with `accel`, not with `column`")),
        _ => {
            return Err(form(
                "give either `column` or `accel` (with `axis`), not both",
            ))
        }
    };
    let path = folder.join(&csv);
    let file_error = |source| SceneError::CsvFile {
        key,
        path: path.clone(),
        source,
    };
    let text = read::text_within(&path, MAX_CSV_LANE_BYTES).map_err(file_error)?;
    let points =
        read_csv_lane(&text, &path, &spec).map_err(|source| SceneError::Csv { key, source })?;
    inputs.push(InputFile::new(key, path, folder));
    Ok(Some(Automation::Points(points)))
}

pub(super) fn automation(
    key: &'static str,
    value: Option<Automation>,
    range: Range,
) -> Result<Automation, SceneError> {
    let automation = value.unwrap_or(Automation::Constant(range.default));
    for value in automation.values() {
        range.check(key, value)?;
    }
    if let Automation::Points(points) = &automation {
        let mut previous = 0.0;
        for (index, &(time_s, _)) in points.iter().enumerate() {
            if !(time_s.is_finite() && time_s >= previous) {
                return Err(SceneError::PointTime { key, index, time_s });
            }
            previous = time_s;
        }
    }
    Ok(automation)
}

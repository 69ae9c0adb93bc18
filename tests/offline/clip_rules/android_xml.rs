//! Validator of Android's vibration XML, as `VibrationXmlParser` reads it: the elements,
//! attributes and ranges of its schema (frameworks/base `core/xsd/vibrator/vibration/
//! vibration.xsd`, version 2.0, as Android 15 ships it) and the checks its parser adds
//! (`VibrationEffectXmlParser`, `SerializedAmplitudeStepWaveform`), and its fixtures. The
//! schema's 2023 draft had the root `<vibration>`, which the parser refuses.

use roxmltree::{Document, Node};

use super::{check_fixtures, Violation};

rules! {
    MalformedXml => "malformed_xml": "the file is well-formed XML",
    WrongRoot => "wrong_root":
        "the root element is <vibration-effect>, in no namespace (the root \
         VibrationXmlParser.parseVibrationEffect and VibrationEffect.parseFromXml read)",
    NotOneEffect => "not_one_effect":
        "<vibration-effect> holds one <waveform-effect>, one <predefined-effect>, or one or \
         more <primitive-effect>, and no other element",
    UnexpectedAttribute => "unexpected_attribute":
        "<vibration-effect>, <waveform-effect> and <repeating> have no attribute",
    UnknownElement => "unknown_element":
        "a <waveform-effect> holds <waveform-entry> elements, then at most one <repeating> \
         of one or more <waveform-entry>, and nothing else",
    EmptyWaveform => "empty_waveform":
        "a <waveform-effect>'s entries last longer than 0 ms together (the schema's assertion \
         as the parser checks it: \"total duration zero\")",
    MissingAttribute => "missing_attribute":
        "every <waveform-entry> has the required durationMs and amplitude, and no other \
         attribute",
    DurationNotNonNegativeInteger => "duration_not_non_negative_integer":
        "durationMs is an xs:nonNegativeInteger that fits a Java int (the parser reads it as \
         one)",
    AmplitudeOutOfRange => "amplitude_out_of_range":
        "amplitude is an integer from 0 to 255, or `default`",
}

/// One waveform entry as read: its duration (ms) and amplitude (−1 for `default`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    pub duration_ms: u64,
    pub amplitude: i32,
}

fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(Node::is_element)
}

fn entry(node: Node, violations: &mut Vec<Violation<Rule>>) -> Option<Entry> {
    let at = format!("entry at byte {}", node.range().start);
    let names: Vec<&str> = node.attributes().map(|a| a.name()).collect();
    let (Some(duration), Some(amplitude)) =
        (node.attribute("durationMs"), node.attribute("amplitude"))
    else {
        violations.push(violation(
            Rule::MissingAttribute,
            format!("{at}: {names:?}"),
        ));
        return None;
    };
    if names.len() != 2 {
        violations.push(violation(
            Rule::MissingAttribute,
            format!("{at}: {names:?}"),
        ));
    }
    let duration_ms = duration
        .trim()
        .parse::<i32>()
        .ok()
        .and_then(|ms| u64::try_from(ms).ok());
    if duration_ms.is_none() {
        violations.push(violation(
            Rule::DurationNotNonNegativeInteger,
            format!("{at}: durationMs={duration:?}"),
        ));
    }
    let amplitude = match amplitude.trim() {
        "default" => Some(-1),
        text => text.parse::<i32>().ok().filter(|a| (0..=255).contains(a)),
    };
    if amplitude.is_none() {
        violations.push(violation(Rule::AmplitudeOutOfRange, at));
    }
    Some(Entry {
        duration_ms: duration_ms?,
        amplitude: amplitude?,
    })
}

/// Reads the entries of every waveform effect, reporting each rule broken into `violations`.
fn read(text: &str, violations: &mut Vec<Violation<Rule>>) -> Vec<Entry> {
    let document = match Document::parse(text) {
        Ok(document) => document,
        Err(e) => {
            violations.push(violation(Rule::MalformedXml, e.to_string()));
            return Vec::new();
        }
    };
    let root = document.root_element();
    if root.tag_name().name() != "vibration-effect" || root.tag_name().namespace().is_some() {
        violations.push(violation(
            Rule::WrongRoot,
            format!("root {:?}", root.tag_name()),
        ));
        return Vec::new();
    }
    let without_attributes = |node: Node, violations: &mut Vec<Violation<Rule>>| {
        if let Some(attribute) = node.attributes().next() {
            violations.push(violation(
                Rule::UnexpectedAttribute,
                format!("<{}> has {}", node.tag_name().name(), attribute.name()),
            ));
        }
    };
    without_attributes(root, violations);
    let effects: Vec<Node> = elements(root).collect();
    let names: Vec<&str> = effects.iter().map(|n| n.tag_name().name()).collect();
    let one_effect = match names.as_slice() {
        ["waveform-effect"] | ["predefined-effect"] => true,
        many => !many.is_empty() && many.iter().all(|name| *name == "primitive-effect"),
    };
    if !one_effect {
        violations.push(violation(Rule::NotOneEffect, format!("{names:?}")));
    }
    let mut entries = Vec::new();
    for effect in effects
        .iter()
        .filter(|n| n.tag_name().name() == "waveform-effect")
    {
        without_attributes(*effect, violations);
        let first_entry = entries.len();
        let mut repeating = false;
        for child in elements(*effect) {
            match child.tag_name().name() {
                "waveform-entry" if !repeating => {
                    entries.extend(entry(child, violations));
                }
                "repeating" if !repeating => {
                    repeating = true;
                    without_attributes(child, violations);
                    let inner: Vec<Node> = elements(child).collect();
                    if inner.is_empty()
                        || inner
                            .iter()
                            .any(|n| n.tag_name().name() != "waveform-entry")
                    {
                        violations.push(violation(Rule::UnknownElement, "in <repeating>"));
                    }
                    for node in inner
                        .into_iter()
                        .filter(|n| n.tag_name().name() == "waveform-entry")
                    {
                        entries.extend(entry(node, violations));
                    }
                }
                other => violations.push(violation(Rule::UnknownElement, other.to_owned())),
            }
        }
        let total_ms: u64 = entries[first_entry..].iter().map(|e| e.duration_ms).sum();
        if total_ms == 0 {
            violations.push(violation(Rule::EmptyWaveform, "total duration 0 ms"));
        }
    }
    entries
}

/// Every rule the text breaks, empty if it is valid.
pub fn validate(text: &str) -> Vec<Violation<Rule>> {
    let mut violations = Vec::new();
    read(text, &mut violations);
    violations
}

/// The entries of a valid file, panicking on any rule it breaks.
pub fn parse(text: &str) -> Vec<Entry> {
    let mut violations = Vec::new();
    let entries = read(text, &mut violations);
    assert!(
        violations.is_empty(),
        "invalid Android XML: {violations:#?}"
    );
    entries
}

#[test]
fn android_xml_fixtures_follow_their_rules() {
    check_fixtures("xml", validate);
}

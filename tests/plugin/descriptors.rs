//! What a host shows of the plugin before it loads it: the CLAP descriptor (through the crate's
//! exported `clap_entry`, as a DAW reads it) and the VST3 factory's and class's information
//! (through the exported `GetPluginFactory`). The project has no public homepage or contact, so
//! those fields are left blank: never a placeholder a host would show to users, and in CLAP no
//! blank string where a field the format lets be absent is absent (NULL).

use std::ffi::{c_char, CStr};

use clap_sys::factory::plugin_factory::{clap_plugin_factory, CLAP_PLUGIN_FACTORY_ID};
use clap_sys::plugin::clap_plugin_descriptor;
use nice_plug::wrapper::vst3::vst3::ComPtr;
use nice_plug::wrapper::vst3::vst3::Steinberg::{
    kResultOk, IPluginFactory, IPluginFactory2, IPluginFactory2Trait, IPluginFactoryTrait,
    PClassInfo2, PFactoryInfo,
};

/// Text no released plugin may show: the domains reserved for examples.
const PLACEHOLDERS: [&str; 4] = [
    "example.invalid",
    "example.com",
    "example.org",
    "example.net",
];

/// `text` holds no placeholder.
fn assert_no_placeholder(field: &str, text: &str) {
    for placeholder in PLACEHOLDERS {
        assert!(
            !text.to_lowercase().contains(placeholder),
            "{field} = {text:?} holds the placeholder {placeholder:?}"
        );
    }
}

/// The text of a NUL-terminated C string, `None` for NULL.
///
/// # Safety
/// `pointer` is NULL or points to a NUL-terminated string.
unsafe fn text(pointer: *const c_char) -> Option<String> {
    (!pointer.is_null()).then(|| {
        unsafe { CStr::from_ptr(pointer) }
            .to_str()
            .unwrap()
            .to_owned()
    })
}

/// The text of a fixed-size, NUL-terminated field of a VST3 info struct.
fn fixed_text(field: &[c_char]) -> String {
    let bytes: Vec<u8> = field
        .iter()
        .take_while(|&&byte| byte != 0)
        .map(|&byte| byte as u8)
        .collect();
    String::from_utf8(bytes).unwrap()
}

/// The one plugin's CLAP descriptor, as a host reads it from the factory.
fn clap_descriptor() -> &'static clap_plugin_descriptor {
    let entry = &sake_glug_plugin::clap_entry;
    unsafe {
        assert!((entry.init.unwrap())(c"".as_ptr()));
        let factory = (entry.get_factory.unwrap())(CLAP_PLUGIN_FACTORY_ID.as_ptr())
            as *const clap_plugin_factory;
        assert!(!factory.is_null());
        assert_eq!(((*factory).get_plugin_count.unwrap())(factory), 1);
        let descriptor = ((*factory).get_plugin_descriptor.unwrap())(factory, 0);
        assert!(!descriptor.is_null());
        &*descriptor
    }
}

#[test]
fn the_clap_descriptor_shows_no_placeholder_and_leaves_out_what_the_project_lacks() {
    let descriptor = clap_descriptor();
    let field = |pointer| unsafe { text(pointer) };
    // Mandatory: set and not blank.
    for (name, pointer) in [("id", descriptor.id), ("name", descriptor.name)] {
        let value = field(pointer).unwrap_or_else(|| panic!("{name} is NULL"));
        assert!(!value.trim().is_empty(), "{name} is blank");
        assert_no_placeholder(name, &value);
    }
    assert_eq!(
        field(descriptor.version).as_deref(),
        Some(env!("CARGO_PKG_VERSION"))
    );
    let vendor = field(descriptor.vendor).expect("a vendor");
    assert!(!vendor.trim().is_empty(), "vendor is blank");
    assert_no_placeholder("vendor", &vendor);
    let description = field(descriptor.description).expect("a description");
    assert!(!description.trim().is_empty(), "description is blank");
    assert_no_placeholder("description", &description);
    // No homepage: nice-plug always passes a string, and the CLAP header lets an optional field
    // be NULL or blank ("safer to make them blank"): blank, not a made-up address.
    assert_eq!(field(descriptor.url).as_deref(), Some(""), "url");
    // No manual or support page: NULL, not a blank string or a placeholder.
    assert_eq!(field(descriptor.manual_url), None, "manual_url");
    assert_eq!(field(descriptor.support_url), None, "support_url");
    // The features: a NULL-terminated list of words, none blank.
    let mut features = Vec::new();
    for index in 0.. {
        let feature = unsafe { *descriptor.features.add(index) };
        let Some(feature) = field(feature) else {
            break;
        };
        assert!(!feature.trim().is_empty(), "feature {index} is blank");
        features.push(feature);
    }
    assert!(features.contains(&"instrument".to_owned()), "{features:?}");
}

#[test]
fn the_vst3_factory_shows_no_placeholder_and_leaves_the_contact_blank() {
    let raw = sake_glug_plugin::GetPluginFactory() as *mut IPluginFactory;
    let factory = unsafe { ComPtr::from_raw(raw) }.expect("a factory");
    let mut info: PFactoryInfo = unsafe { std::mem::zeroed() };
    assert_eq!(unsafe { factory.getFactoryInfo(&mut info) }, kResultOk);
    let vendor = fixed_text(&info.vendor);
    assert!(!vendor.trim().is_empty(), "vendor is blank");
    assert_no_placeholder("vendor", &vendor);
    // No homepage or contact address: the fixed-size fields are left empty, the format's only
    // way to say "none".
    assert_eq!(fixed_text(&info.url), "", "url");
    assert_eq!(fixed_text(&info.email), "", "email");

    let factory2 = factory.cast::<IPluginFactory2>().expect("IPluginFactory2");
    let count = unsafe { factory.countClasses() };
    assert!(count >= 1);
    for index in 0..count {
        let mut class: PClassInfo2 = unsafe { std::mem::zeroed() };
        assert_eq!(
            unsafe { factory2.getClassInfo2(index, &mut class) },
            kResultOk
        );
        for (name, value) in [
            ("name", &class.name[..]),
            ("vendor", &class.vendor[..]),
            ("version", &class.version[..]),
        ] {
            let value = fixed_text(value);
            assert!(!value.trim().is_empty(), "class {index}: {name} is blank");
            assert_no_placeholder(name, &value);
        }
    }
}

/// The plugin's own parameters by name: whether each is a float (continuous) parameter.
fn float_by_name() -> std::collections::HashMap<String, bool> {
    use nice_plug::prelude::{ParamPtr, Params};
    sake_glug_plugin::GlugParams::default()
        .param_map()
        .into_iter()
        .map(|(_, param, _)| {
            let name = unsafe { param.name() }.to_owned();
            (name, matches!(param, ParamPtr::FloatParam(_)))
        })
        .collect()
}

/// Each float parameter is continuous to the host: VST3 stepCount 0 and no CLAP "stepped"
/// flag, so a host's value (typed or automated) reaches the plugin as it is; the knob's step
/// is only in the text the plugin shows and parses. The integer and enum parameters come out
/// stepped, which shows that the counts read here are the plugin's own.
#[test]
fn every_float_parameter_is_continuous_to_vst3_and_clap_hosts() {
    use clap_sys::ext::params::CLAP_PARAM_IS_STEPPED;
    use nice_plug::wrapper::vst3::vst3::Steinberg::Vst::{
        IComponent, IComponent_iid, IEditController, IEditControllerTrait, ParameterInfo,
    };
    let floats = float_by_name();
    assert!(floats.values().filter(|&&float| float).count() >= 17);

    let raw = sake_glug_plugin::GetPluginFactory() as *mut IPluginFactory;
    let factory = unsafe { ComPtr::from_raw(raw) }.expect("a factory");
    let factory2 = factory.cast::<IPluginFactory2>().expect("IPluginFactory2");
    let mut class: PClassInfo2 = unsafe { std::mem::zeroed() };
    assert_eq!(unsafe { factory2.getClassInfo2(0, &mut class) }, kResultOk);
    let mut object = std::ptr::null_mut();
    let created =
        unsafe { factory.createInstance(class.cid.as_ptr(), IComponent_iid.as_ptr(), &mut object) };
    assert_eq!(created, kResultOk);
    let component = unsafe { ComPtr::from_raw(object as *mut IComponent) }.expect("IComponent");
    let controller = component
        .cast::<IEditController>()
        .expect("IEditController");
    let count = unsafe { controller.getParameterCount() };
    assert_eq!(
        count as usize,
        floats.len(),
        "the VST3 has only the real parameters"
    );
    for index in 0..count {
        let mut info: ParameterInfo = unsafe { std::mem::zeroed() };
        assert_eq!(
            unsafe { controller.getParameterInfo(index, &mut info) },
            kResultOk
        );
        let title: Vec<u16> = info.title.iter().copied().take_while(|&c| c != 0).collect();
        let title = String::from_utf16(&title).unwrap();
        let float = floats[&title];
        assert_eq!(
            info.stepCount == 0,
            float,
            "VST3 {title}: stepCount {}",
            info.stepCount
        );
    }

    let instance = crate::clap_host::ClapInstance::new();
    let infos = instance.parameter_infos();
    assert_eq!(infos.len(), floats.len());
    for (name, flags) in infos {
        let stepped = flags & CLAP_PARAM_IS_STEPPED != 0;
        assert_eq!(!stepped, floats[&name], "CLAP {name}: flags {flags:#x}");
    }
}

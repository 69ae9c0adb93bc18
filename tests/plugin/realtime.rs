//! process() is real-time safe: no allocation (checked by nice-plug's `assert_no_alloc` when
//! built with `--features assert_process_allocs` in the dev profile), under every kind of input a
//! host sends: odd block sizes, parameter changes, note-ons, CCs, transport starts and jumps, an
//! actuator chosen or cleared.
//!
//! Run: `cargo test --features assert_process_allocs --test plugin realtime`

use nice_plug::prelude::Plugin;

use crate::host::{cc, note_on, peak, Playhead, TestHost};

#[cfg(all(debug_assertions, feature = "assert_process_allocs"))]
fn no_alloc(f: &mut dyn FnMut()) {
    nice_assert_no_alloc::assert_no_alloc(f)
}

#[cfg(not(all(debug_assertions, feature = "assert_process_allocs")))]
fn no_alloc(f: &mut dyn FnMut()) {
    f()
}

fn host(sample_rate: f32, channels: usize) -> TestHost {
    let mut host = TestHost::new(sample_rate, channels);
    host.guard = no_alloc;
    host
}

#[test]
fn process_does_not_allocate_under_a_busy_session() {
    for (sample_rate, channels) in [(48_000.0, 2), (44_100.0, 1), (1_000.0, 2), (768_000.0, 1)] {
        let mut host = host(sample_rate, channels);
        host.set_text("tilt", "135");
        let mut heard = 0.0f32;
        let mut position = 0i64;
        for (index, len) in [1usize, 7, 32, 512, 4096, 333, 64, 8192, 128]
            .into_iter()
            .cycle()
            .take(60)
            .enumerate()
        {
            // Parameter changes between blocks, as a wrapper applies them.
            match index % 6 {
                0 => host.set_normalized("visc", (index as f32 * 0.137) % 1.0),
                1 => host.set_normalized("pour", (index as f32 * 0.291) % 1.0),
                2 => host.set_normalized("f2", (index as f32 * 0.53) % 1.0),
                3 => host.set_normalized("seed", (index as f32 * 0.07) % 1.0),
                4 => host.set_normalized("drain", (index % 2) as f32),
                _ => host.set_normalized("b1", (index as f32 * 0.77) % 1.0),
            }
            // The editor picks an actuator (or none) between blocks: process() takes it.
            if index % 4 == 2 {
                let names = ["lra", "phone", "none", "haptuator-mark2"];
                let actuator =
                    sake_glug_plugin::Actuator::shipped(names[index / 4 % 4], index % 8 == 2);
                host.plugin.glug_params().actuator.set(actuator);
            }
            // The editor arms MIDI learn now and then: process() takes the next CC for it.
            if index % 5 == 1 {
                let rows: Vec<_> = sake_glug_device::midi::MidiSetting::all().skip(1).collect();
                let row = rows[index / 5 % rows.len()];
                host.plugin.glug_params().learn.arm(row);
            }
            let last = len as u32 - 1;
            let events = vec![
                cc(0, 0, 16, 100),
                cc(last / 2, 0, 48, 5),
                cc(last, 3, 17, 64),
                note_on(last / 3),
                cc(last, 0, 18, 127),
            ];
            // Play, then jump, then stop now and then.
            let playhead = match index % 10 {
                9 => Playhead::default(),
                5 => Playhead {
                    playing: true,
                    position: Some(1_000_000),
                },
                _ => Playhead {
                    playing: true,
                    position: Some(position),
                },
            };
            let out = host.process(len, events, playhead);
            position += len as i64;
            for channel in &out {
                assert!(channel.iter().all(|s| s.is_finite()));
                assert_eq!(channel, &out[0], "every channel carries the mono signal");
            }
            heard = heard.max(peak(&out[0]));
            // Hosts may call reset() from the audio thread at any time.
            if index % 7 == 3 {
                let plugin = &mut host.plugin;
                no_alloc(&mut || plugin.reset());
            }
        }
        assert!(
            heard > 0.0,
            "the session at {sample_rate} Hz must make sound"
        );
    }
}

/// OSC arriving from a socket thread while `process()` runs: the audio thread only reads atomics.
#[test]
fn process_does_not_allocate_while_osc_arrives() {
    let plugin = sake_glug_plugin::SakeGlug::default();
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").expect("a free port");
    let port = socket.local_addr().expect("its address").port();
    drop(socket);
    plugin
        .glug_params()
        .osc
        .set(port, sake_glug_device::Axis::PlusY);
    plugin.osc().allow(port);
    let mut host = TestHost::with_plugin(plugin, 48_000.0, 2);
    host.guard = no_alloc;
    let client = std::net::UdpSocket::bind("127.0.0.1:0").expect("client socket");
    let mut heard = 0.0f32;
    for index in 0..200u32 {
        // Refills are rare: the first glug of a full bottle needs 5 ml of outflow, ~80 ms.
        let message = match index % 4 {
            _ if index == 150 => ("/sakeglug/refill", vec![]),
            0 => (
                "/sakeglug/tilt",
                vec![rosc::OscType::Float(100.0 + (index % 80) as f32)],
            ),
            1 => ("/sakeglug/viscosity", vec![rosc::OscType::Float(0.5)]),
            2 => ("/gyrosc/grav", vec![rosc::OscType::Float(0.3); 3]),
            _ => ("/sakeglug/fill", vec![rosc::OscType::Int(90)]),
        };
        let bytes = rosc::encoder::encode(&rosc::OscPacket::Message(rosc::OscMessage {
            addr: message.0.to_owned(),
            args: message.1,
        }))
        .expect("encode");
        client
            .send_to(&bytes, ("127.0.0.1", port))
            .expect("send over loopback");
        // Every other block waits for the socket thread, so that values do arrive mid-session.
        let stats = host.plugin.osc().stats();
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
        while index % 2 == 0
            && stats.packets.load(std::sync::atomic::Ordering::Relaxed) <= index as u64
        {
            assert!(
                std::time::Instant::now() < deadline,
                "the listener reads the packets"
            );
            std::thread::yield_now();
        }
        let out = host.process(240, Vec::new(), Playhead::default());
        heard = heard.max(peak(&out[0]));
    }
    assert!(
        host.plugin
            .osc()
            .stats()
            .packets
            .load(std::sync::atomic::Ordering::Relaxed)
            > 0
    );
    assert!(heard > 0.0, "OSC tilt made the bottle glug");
}

/// Proves the check above is armed: an allocation inside the same guard aborts the process.
/// Runs itself as a child process, because the abort cannot be caught.
#[cfg(all(debug_assertions, feature = "assert_process_allocs"))]
#[test]
fn an_allocation_inside_the_guard_is_caught() {
    if std::env::var_os("SAKE_GLUG_ALLOC_CANARY").is_some() {
        no_alloc(&mut || {
            let leaked = std::hint::black_box(vec![1u8; 64]);
            std::hint::black_box(&leaked);
        });
        return;
    }
    // The test's name as the harness knows it: its module path without the crate's name.
    let module = module_path!()
        .split_once("::")
        .map_or("", |(_, module)| module);
    let name = format!("{module}::an_allocation_inside_the_guard_is_caught");
    let status = std::process::Command::new(std::env::current_exe().expect("test binary path"))
        .args(["--exact", &name, "--nocapture"])
        .env("SAKE_GLUG_ALLOC_CANARY", "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .output()
        .expect("run the canary");
    // The child must have run the canary (one test), not matched nothing and passed.
    let listing = String::from_utf8_lossy(&status.stdout);
    assert!(listing.contains("running 1 test"), "{listing}");
    assert!(
        !status.status.success(),
        "an allocation inside assert_no_alloc went unnoticed"
    );
}

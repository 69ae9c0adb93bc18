-- Bounces Sake Glug's VST3 in Ardour (headless `ardour7-lua`, dummy backend, 48 kHz): a MIDI
-- track with the plugin, its Tilt automated through the points of GLUG_POINTS (one "sample
-- degrees" pair a line), exported as 32-bit float WAV to GLUG_OUT/bounce.wav.
-- Also writes GLUG_OUT/delivered.txt: the list's points as Ardour kept them ("point SAMPLE VALUE",
-- on a MIDI track rounded to its beat grid), the engine's cycle ("cycle SAMPLES"), and for every
-- cycle of the export the parameter queue Ardour 7.3 hands the VST3 ("queue START OFFSET VALUE",
-- Tilt in degrees before the plugin normalises it). Ardour builds that queue in
-- PluginInsert::connect_and_run (libs/ardour/plugin_insert.cc in Ardour's sources): a VST3's
-- cycle is never split (automate_and_run); it is handed the list's value at the cycle's start
-- (offset 0), then each point strictly inside the cycle (the test's points lie on whole samples)
-- at its own offset with the list's value there (only the points: none is interpolated between
-- them), then the value at the cycle's end at offset CYCLE, one past its last sample
-- (libs/ardour/vst3_plugin.cc queues each as it comes; a later value at the same offset replaces
-- an earlier one). The values come from the list's own evaluation (eval, as its rt_safe_eval), so
-- they are Ardour's to the last bit.
-- Needs the plugin scanned first and the export preset GLUG_PRESET installed (the test does both).
local points_file = assert(os.getenv("GLUG_POINTS"))
local length = assert(tonumber(os.getenv("GLUG_LENGTH")))
local out = assert(os.getenv("GLUG_OUT"))

AudioEngine:set_backend("None (Dummy)", "", "")
assert(create_session(assert(os.getenv("GLUG_SESSION")), "bounce", 48000))
local info = ARDOUR.LuaAPI.new_plugin_info("Sake Glug", ARDOUR.PluginType.VST3)
assert(not info:isnil(), "Sake Glug's VST3 was not scanned")
local midi = ARDOUR.ChanCount(ARDOUR.DataType("midi"), 1)
local tracks = Session:new_midi_track(midi, midi, true, info, nil, nil, 1, "Glug",
  ARDOUR.PresentationInfo.max_order, ARDOUR.TrackMode.Normal, false, false)
local plugin = tracks:front():nth_plugin(0)
assert(not plugin:isnil(), "the track has no plugin")

-- Tilt is the plugin's first parameter; Ardour lists it in degrees.
local _, list, descriptor = ARDOUR.LuaAPI.plugin_automation(plugin, 0)
assert(descriptor.upper == 180, "the first parameter is not Tilt")
list:clear_list()
for line in io.lines(points_file) do
  local at, value = line:match("(%S+)%s+(%S+)")
  list:add(Temporal.timepos_t(tonumber(at)), tonumber(value), false, false)
end
-- The automation state is the control's, not the list's.
plugin:to_automatable()
  :automation_control(Evoral.Parameter(ARDOUR.AutomationType.PluginAutomation, 0, 0), false)
  :set_automation_state(ARDOUR.AutoState.Play)

local log = io.open(out .. "/delivered.txt", "w")
local kept = {}
for event in list:events():iter() do
  local at = event.when:samples()
  kept[#kept + 1] = { at = at, when = event.when }
  log:write(string.format("point %d %.17g\n", at, event.value))
end
local cycle = Session:get_block_size()
log:write(string.format("cycle %d\n", cycle))
local function queue(start, offset, when)
  log:write(string.format("queue %d %d %.17g\n", start, offset, list:eval(when)))
end
for start = 0, length - 1, cycle do
  queue(start, 0, Temporal.timepos_t(start))
  for _, point in ipairs(kept) do
    if start < point.at and point.at < start + cycle then
      queue(start, point.at - start, point.when)
    end
  end
  queue(start, cycle, Temporal.timepos_t(start + cycle))
end
log:close()

local export = Session:simple_export()
assert(export:set_preset(assert(os.getenv("GLUG_PRESET"))), "no export preset")
export:set_folder(out)
export:set_range(0, length)
assert(export:run_export(), "the export failed")
-- Said before the session closes: Ardour 7.3 sometimes aborts while it tears down.
print("bounced")
close_session()
quit()

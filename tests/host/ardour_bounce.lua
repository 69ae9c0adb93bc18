-- Bounces Sake Glug's VST3 in Ardour (headless `ardour7-lua`, dummy backend, 48 kHz, 1024-sample
-- cycles): a MIDI track with the plugin, its Tilt automated through the points of GLUG_POINTS
-- (one "sample degrees" pair a line), exported as 32-bit float WAV to GLUG_OUT/bounce.wav.
-- Also writes GLUG_OUT/delivered.txt: the list's points as Ardour kept them ("point SAMPLE
-- VALUE", on a MIDI track rounded to its beat grid) and its value at every cycle boundary
-- ("cycle SAMPLE VALUE"), from which the test rebuilds what the plugin was handed.
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
for event in list:events():iter() do
  log:write(string.format("point %d %.17g\n", event.when:samples(), event.value))
end
for cycle = 0, length // 1024 + 1 do
  local at = cycle * 1024
  log:write(string.format("cycle %d %.17g\n", at, list:eval(Temporal.timepos_t(at))))
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

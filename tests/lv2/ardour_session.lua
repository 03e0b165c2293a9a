-- An Ardour session with the dpc LV2 plugin, run headless by Ardour's Lua session tool
-- (ardour7-lua, Debian's ardour package), as tests/lv2/ardour_test.py drives it:
--   ardour7-lua ardour_session.lua SESSION_DIR EXPORT_DIR URI|none [WAIT]
-- Creates a session on the dummy audio backend (its inputs play white noise), adds a mono
-- track whose input monitors that noise, inserts the plugin URI, plays until the track's meter
-- shows sound (the plugin is silent until its scene has loaded in the background; at most
-- WAIT s, 120 by default) and 1 s more, exports 4 s of the master bus to EXPORT_DIR/created.wav (WAV at the
-- session rate), saves and closes the session; then loads it again from disk, plays and
-- exports EXPORT_DIR/reloaded.wav and closes it. Prints "dpc-test: <step>" after each step, so
-- that the driver can tell where a run stopped; the exit status is Ardour's own.
local dir, export_dir, uri = arg[1], arg[2], arg[3]
local max_wait = tonumber(arg[4] or "120")
assert(dir and export_dir and uri, "usage: ardour_session.lua SESSION_DIR EXPORT_DIR URI [WAIT]")
local rate = 48000
-- Ardour's "WAV @ session-rate" export preset (export/wav.preset): 32-bit float WAV
local wav_preset = "75969a1c-3133-4694-864b-a1fa50e43348"

local function step(what) print("dpc-test: " .. what) io.stdout:flush() end

-- Plays until the track's output meter reads above -60 dBFS (or max_wait s have passed) and 1 s
-- more, then exports 4 s from the session start to export_dir/name.wav.
local function play_and_export(s, track, name)
  local waited = 0
  while track:peak_meter():meter_level(0, ARDOUR.MeterType.MeterPeak) < -60 and waited < max_wait do
    sleep(0.25)
    waited = waited + 0.25
  end
  step(string.format("sound after %.2f s", waited))
  sleep(1)
  local e = s:simple_export()
  e:set_preset(wav_preset)
  e:set_folder(export_dir)
  e:set_name(name)
  e:set_range(0, 4 * rate)
  assert(e:run_export(), "export failed")
  step("exported " .. name)
end

local function dpc_plugin(track)
  local i = 0
  while true do
    local proc = track:nth_plugin(i)
    if proc:isnil() then return nil end
    if proc:to_insert():plugin(0):unique_id() == uri then return proc end
    i = i + 1
  end
end

assert(AudioEngine:set_backend("None (Dummy)", "", ""), "no dummy backend")
assert(AudioEngine:set_device_name("Uniform White Noise") == 0, "the dummy backend has no noise input")
local s = create_session(dir, "dpc", rate)
assert(s, "create_session failed")
step("created")
local track = s:new_audio_track(1, 2, nil, 1, "dpc", ARDOUR.PresentationInfo.max_order,
                                ARDOUR.TrackMode.Normal, true):front()
-- URI "none": the same session without a plugin (Ardour alone, the test's control).
if uri ~= "none" then
  local plugin = ARDOUR.LuaAPI.new_plugin(s, uri, ARDOUR.PluginType.LV2, "")
  assert(not plugin:isnil(), "Ardour does not find the plugin " .. uri)
  assert(track:add_processor_by_index(plugin, 0, nil, true) == 0, "the plugin was not added")
end
track:monitoring_control():set_value(ARDOUR.MonitorChoice.MonitorInput,
                                     PBD.GroupControlDisposition.NoGroup)
step("plugin added")
play_and_export(s, track, "created")
assert(s:save_state("", false, false, false, false, false) == 0, "save failed")
step("saved")
close_session()
step("closed")

s = load_session(dir, "dpc")
assert(s, "load_session failed")
track = s:route_by_name("dpc"):to_track()
assert(not track:isnil(), "the reloaded session has no track dpc")
assert(uri == "none" or dpc_plugin(track), "the reloaded track has no " .. uri)
step("reloaded")
play_and_export(s, track, "reloaded")
close_session()
step("closed again")

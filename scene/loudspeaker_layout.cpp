#include "scene/loudspeaker_layout.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "common/input_error.h"
#include "scene/json_reader.h"
#include "scene/limits.h"
#include "scene/validate.h"

namespace dpc {
namespace {

std::vector<LoudspeakerDesc> preset(const std::string& name) {
  std::vector<LoudspeakerDesc> l = {{"L", 30, 0, false}, {"R", -30, 0, false},
                                    {"C", 0, 0, false},  {"LFE", 0, 0, true}};
  if (name == "5.1") {
    l.push_back({"Ls", 110, 0, false});
    l.push_back({"Rs", -110, 0, false});
    return l;
  }
  if (name != "7.1" && name != "7.1.4") return {};
  l.insert(l.end(), {{"Lrs", 135, 0, false},
                     {"Rrs", -135, 0, false},
                     {"Lss", 90, 0, false},
                     {"Rss", -90, 0, false}});
  if (name == "7.1.4")
    l.insert(l.end(), {{"Ltf", 45, 30, false},
                       {"Rtf", -45, 30, false},
                       {"Ltr", 135, 30, false},
                       {"Rtr", -135, 30, false}});
  return l;
}

double angleBetween(const LoudspeakerDesc& a, const LoudspeakerDesc& b) {
  constexpr double d = std::numbers::pi / 180.0;
  const double c = std::sin(a.elevationDegrees * d) * std::sin(b.elevationDegrees * d) +
                   std::cos(a.elevationDegrees * d) * std::cos(b.elevationDegrees * d) *
                       std::cos((a.azimuthDegrees - b.azimuthDegrees) * d);
  return std::acos(std::clamp(c, -1.0, 1.0)) / d;
}

LoudspeakerDesc readSpeaker(const JsonReader& r, const nlohmann::json& v, const std::string& f) {
  r.expectObject(v, f);
  r.checkKeys(v, f, {"name", "azimuth", "elevation", "lfe", "distance"});
  LoudspeakerDesc s;
  s.name = r.string(r.require(v, f, "name"), join(f, "name"));
  checkName(s.name, false, Origin{r.file(), {}}, join(f, "name"));
  if (const auto* x = JsonReader::find(v, "lfe")) s.lfe = r.boolean(*x, join(f, "lfe"));
  if (s.lfe) return s;
  s.azimuthDegrees = r.number(r.require(v, f, "azimuth"), join(f, "azimuth"));
  if (const auto* x = JsonReader::find(v, "elevation"))
    s.elevationDegrees = r.number(*x, join(f, "elevation"));
  if (std::abs(s.azimuthDegrees) > 180) r.fail(join(f, "azimuth"), "outside [-180, 180] degrees");
  if (std::abs(s.elevationDegrees) > 90) r.fail(join(f, "elevation"), "outside [-90, 90] degrees");
  if (const auto* x = JsonReader::find(v, "distance")) {
    s.distanceMetres = r.number(*x, join(f, "distance"));
    if (!(s.distanceMetres >= kMinLoudspeakerDistance &&
          s.distanceMetres <= kMaxLoudspeakerDistance))
      r.fail(join(f, "distance"), "outside [" + valueText(kMinLoudspeakerDistance) +
                                      ", " + valueText(kMaxLoudspeakerDistance) +
                                      "] m");
  }
  return s;
}

/// Distances on every loudspeaker that is not LFE, or on none.
void checkDistances(const JsonReader& r, const std::vector<LoudspeakerDesc>& l) {
  bool any = false;
  for (const auto& s : l) any = any || s.distanceMetres > 0;
  if (!any) return;
  for (size_t i = 0; i < l.size(); ++i)
    if (!l[i].lfe && l[i].distanceMetres == 0)
      r.fail(join(index("speakers", i), "distance"),
             "missing: give every loudspeaker a distance, or none");
}

std::vector<LoudspeakerDesc> readFile(const std::string& path) {
  const nlohmann::json doc = parseJsonFile(path, "layout file");
  const JsonReader r(path);
  r.expectObject(doc, "");
  r.checkKeys(doc, "", {"speakers"});
  const nlohmann::json& list = r.require(doc, "", "speakers");
  if (!list.is_array() || list.size() < 2 || list.size() > kMaxLoudspeakers)
    r.fail("speakers", "must be a list of 2 .. " + std::to_string(kMaxLoudspeakers) +
                           " loudspeakers");
  std::vector<LoudspeakerDesc> out;
  std::set<std::string> names;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string f = index("speakers", i);
    out.push_back(readSpeaker(r, list[i], f));
    if (!names.insert(out.back().name).second) r.fail(join(f, "name"), "duplicated name");
    for (size_t j = 0; j + 1 < out.size(); ++j)
      if (!out.back().lfe && !out[j].lfe && angleBetween(out.back(), out[j]) < 1.0)
        r.fail(f, "within 1 degree of " + index("speakers", j) + " (duplicated direction)");
  }
  size_t real = 0;
  for (const auto& s : out) real += !s.lfe;
  if (real < 2) r.fail("speakers", "needs at least two loudspeakers that are not LFE");
  checkDistances(r, out);
  return out;
}

}  // namespace

std::vector<DistanceCompensation> distanceCompensation(const std::vector<LoudspeakerDesc>& layout,
                                                       double speedOfSound, int sampleRate) {
  double farthest = 0.0;
  for (const auto& s : layout)
    if (!s.lfe) farthest = std::max(farthest, s.distanceMetres);
  std::vector<DistanceCompensation> out(layout.size());
  if (farthest <= 0.0) return out;
  for (size_t i = 0; i < layout.size(); ++i) {
    if (layout[i].lfe || layout[i].distanceMetres <= 0.0) continue;
    const double d = layout[i].distanceMetres;
    out[i].delaySamples = size_t(std::lround((farthest - d) / speedOfSound * sampleRate));
    out[i].gain = d / farthest;
  }
  return out;
}

std::vector<LoudspeakerDesc> loudspeakerLayout(const std::string& spec, const std::string& flag) {
  std::vector<LoudspeakerDesc> l = preset(spec);
  if (!l.empty()) return l;
  if (spec.size() > 5 && spec.substr(spec.size() - 5) == ".json") return readFile(spec);
  throw InputError("command line", flag,
                   "'layout:" + spec + "' is not layout:5.1, layout:7.1, layout:7.1.4 or "
                   "layout:FILE.json");
}

}  // namespace dpc

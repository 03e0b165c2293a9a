#include "bake/parameter_map.h"

#include <cstdio>

#include "common/output_file.h"

namespace dpc::bake {
namespace {

std::string number(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", double(v));
  return buf;
}

std::string bandName(int row) {
  return row < kNumBands ? number(kBandCentreHz[size_t(row)]) : std::string("broadband");
}

}  // namespace

void writeParameterMap(const BakeFile& bake, const std::string& csvPath) {
  const BakeHeader& h = bake.header();
  const auto done = bake.done();
  const auto params = bake.readAll("parameters");
  const auto ci = bake.readAll("parameters_ci95");
  const auto sti = bake.readAll("sti");
  const auto stiCi = bake.readAll("sti_ci95");
  const size_t sources = h.shape.sources;
  std::string text = "probe,x_m,y_m,z_m,source,parameter,band,value,ci95\n";
  for (size_t p = 0; p < done.size(); ++p) {
    if (!done[p]) continue;
    const glm::vec3& x = h.probes.positions[p];
    const std::string where = std::to_string(p) + "," + number(x.x) + "," + number(x.y) + "," +
                              number(x.z) + ",";
    for (size_t s = 0; s < sources; ++s) {
      const std::string head = where + std::to_string(s) + ",";
      for (int row = 0; row < kParameterRows; ++row)
        for (int k = 0; k < kParameters; ++k) {
          const size_t i = ((p * sources + s) * kParameterRows + size_t(row)) * kParameters + size_t(k);
          text += head + kParameterNames[size_t(k)] + "," + bandName(row) + "," +
                  number(params[i]) + "," + number(ci[i]) + "\n";
        }
      text += head + "STI,broadband," + number(sti[p * sources + s]) + "," +
              number(stiCi[p * sources + s]) + "\n";
    }
  }
  TempOutputFile out(csvPath);
  out.writeAll(text.data(), text.size());
  out.commit();
}

}  // namespace dpc::bake

#include "api/layouts.h"

#include "api/errors.h"
#include "common/text_buffer.h"

namespace dpc::api {

dpc_status checkLayout(const char* name, std::span<const Layout> known, size_t size) {
  for (const Layout& layout : known)
    if (layout.size == size) return DPC_OK;
  char field[48], problem[224];
  TextBuffer(field, sizeof field) << name << ".struct_size";
  TextBuffer text(problem, sizeof problem);
  text << (long long)size << " bytes is not a layout this library (dpc " DPC_VERSION_STRING
       << ") knows:";
  for (const Layout& layout : known)
    text << " " << (long long)layout.size << " (" << layout.releases << ")";
  text << "; compile against a dpc.h of one of those releases";
  return failFixed(DPC_ERR_VERSION, field, problem);
}

}  // namespace dpc::api

// The single-producer single-consumer queue dpc hands buffers through: moodycamel's
// ReaderWriterQueue (Debian libreaderwriterqueue-dev). Include it through this header.
//
// Under ThreadSanitizer the queue's fence-based synchronisation is invisible unless it is
// annotated; readerwriterqueue annotates it only under Clang, so for GCC's -fsanitize=thread we
// supply the same AnnotateHappensBefore/After hooks (TSan's dynamic-annotation interface)
// before the library header is seen. Without sanitizers this header adds nothing.
// Use: fixed capacity at construction; only try_enqueue/try_dequeue (never allocate).
#pragma once

#if defined(__SANITIZE_THREAD__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wtsan"
#endif
#if defined(__SANITIZE_THREAD__) && !defined(AE_TSAN_ANNOTATE_RELEASE)
namespace moodycamel {
inline int ae_tsan_global;
}
extern "C" void AnnotateHappensBefore(const char*, int, void*);
extern "C" void AnnotateHappensAfter(const char*, int, void*);
#define AE_TSAN_ANNOTATE_RELEASE() \
  AnnotateHappensBefore(__FILE__, __LINE__, (void*)(&::moodycamel::ae_tsan_global))
#define AE_TSAN_ANNOTATE_ACQUIRE() \
  AnnotateHappensAfter(__FILE__, __LINE__, (void*)(&::moodycamel::ae_tsan_global))
#endif

#include <readerwriterqueue/readerwriterqueue.h>

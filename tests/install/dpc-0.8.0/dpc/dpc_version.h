/* dpc version macros (C99), configured by CMake from project(dpc VERSION ...) into the build
 * tree and installed beside dpc.h. A program compares the header it was compiled with
 * (DPC_VERSION) and the library it runs with (dpc_version(), dpc.h): by the growth rule (dpc.h)
 * a library serves the programs compiled against its own or an older release of its major
 * version, from 0.5.0 on. */
#ifndef DPC_DPC_VERSION_H
#define DPC_DPC_VERSION_H

#define DPC_VERSION_MAJOR 0
#define DPC_VERSION_MINOR 8
#define DPC_VERSION_PATCH 0
/** "MAJOR.MINOR.PATCH" */
#define DPC_VERSION_STRING "0.8.0"

/** Packs a version into one unsigned long, ordered as versions are: major in bits 16..,
 *  minor in bits 8..15, patch in bits 0..7 (minor and patch 0..255). Usable in #if. */
#define DPC_MAKE_VERSION(major, minor, patch) \
  ((major) * 65536UL + (minor) * 256UL + (patch) * 1UL)
/** This header's version, packed (DPC_MAKE_VERSION). */
#define DPC_VERSION DPC_MAKE_VERSION(DPC_VERSION_MAJOR, DPC_VERSION_MINOR, DPC_VERSION_PATCH)
/** True when a library of packed version `library` (dpc_version()) serves a program compiled
 *  against this header: the same major version, and not older than this header. */
#define DPC_VERSION_COMPATIBLE(library) \
  (((library) >> 16) == DPC_VERSION_MAJOR && (library) >= DPC_VERSION)

#endif /* DPC_DPC_VERSION_H */

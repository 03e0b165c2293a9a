/* dpc version macros (C99), configured by CMake from project(dpc VERSION ...) into the build
 * tree and installed beside dpc.h. A program compares the header it was compiled with
 * (DPC_VERSION) and the library it runs with (dpc_version(), dpc.h): while the major version is
 * 0, every minor version may change the ABI, so both must agree on major and minor. */
#ifndef DPC_DPC_VERSION_H
#define DPC_DPC_VERSION_H

#define DPC_VERSION_MAJOR 0
#define DPC_VERSION_MINOR 6
#define DPC_VERSION_PATCH 0
/** "MAJOR.MINOR.PATCH" */
#define DPC_VERSION_STRING "0.6.0"

/** Packs a version into one unsigned long, ordered as versions are: major in bits 16..,
 *  minor in bits 8..15, patch in bits 0..7 (minor and patch 0..255). Usable in #if. */
#define DPC_MAKE_VERSION(major, minor, patch) \
  ((major) * 65536UL + (minor) * 256UL + (patch) * 1UL)
/** This header's version, packed (DPC_MAKE_VERSION). */
#define DPC_VERSION DPC_MAKE_VERSION(DPC_VERSION_MAJOR, DPC_VERSION_MINOR, DPC_VERSION_PATCH)

#endif /* DPC_DPC_VERSION_H */

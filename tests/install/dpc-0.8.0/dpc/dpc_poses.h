/* dpc C API, poses (C99): where listeners, sources and moving objects stand and how they are
 * turned while an engine runs. Included by dpc/dpc.h (include that); its thread roles, errors
 * and lifetime rule apply here.
 *
 * Frame and rotations (one convention for every pose): a right-handed world frame, metres,
 * +y up (scene files and meshes use the same). A rotation is a unit quaternion in glTF order
 * (x, y, z, w) that maps an object's local frame to the world: world = R(q) * local + position.
 * A listener's and a source's rest pose (q = identity) faces +x with +y up. Listeners are also
 * described by yaw, pitch and roll in degrees, in the same frame (the spatial synthesis and the
 * head rotation read the listener's forward and up directions): at yaw 0, pitch 0, roll 0 it
 * faces +x with +y up; yaw turns it about +y, positive to the left (+x towards -z); pitch then
 * raises its gaze, positive up; roll then tilts the head about its forward direction, positive
 * to its right (the right ear down). dpc_yaw_pitch_roll_from_quaternion converts between the
 * two (the quaternion rotates the rest pose). */
#ifndef DPC_DPC_POSES_H
#define DPC_DPC_POSES_H

#include "dpc/dpc.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A pose in the frame above: a position and a rotation (since 0.7.0). A plain value, not
 *  versioned (no struct_size): it never changes. */
typedef struct dpc_pose {
  float position[3]; /**< x, y, z, metres; each within +-10^6 m (the scene file's "position"
                          limit) */
  float rotation[4]; /**< x, y, z, w (glTF order), local to world; any finite non-zero length
                          (normalised here); {0, 0, 0, 1} is the rest pose */
} dpc_pose;

/** Any thread (one writer per listener at a time), wait-free, no allocation. Places listener
 *  `listener` (0-based, the scene's "listeners" order; dpc_engine_selected_listener() for the
 *  one heard) at pose->position, turned from its rest pose by pose->rotation: forward
 *  R(q) * (1, 0, 0), up R(q) * (0, 1, 0) (the yaw, pitch and roll of
 *  dpc_yaw_pitch_roll_from_quaternion). The propagation thread uses the newest pose at its next
 *  frame; a head-tracked output (DPC_OUTPUT_AMBISONIC_BINAURAL) turns its sound field from the
 *  next audio block. Until the first call a listener stands where the scene puts it at time 0
 *  (its position or first keyframe). Errors, with nothing changed and dpc_last_error() naming
 *  the field (e.g. "dpc_engine_place_listener: pose.position[0]: 1e+07 is outside [-1000000,
 *  1000000] m"): DPC_ERR_INVALID_ARGUMENT (NULL engine or pose, index out of range, a
 *  coordinate beyond its limit or not finite, a zero or non-finite rotation), DPC_ERR_STATE
 *  (the engine is being destroyed). Since 0.7.0. */
DPC_API dpc_status dpc_engine_place_listener(dpc_engine* engine, int listener,
                                             const dpc_pose* pose);

/** As dpc_engine_place_listener, for source `source` (0-based, scene order): its position and
 *  its directivity's orientation (forward axis R(q) * (1, 0, 0); an omnidirectional source
 *  sounds the same whatever the rotation) replace its trajectory and keyframes from the next
 *  propagation frame on. Since 0.7.0. */
DPC_API dpc_status dpc_engine_place_source(dpc_engine* engine, int source, const dpc_pose* pose);

/** As dpc_engine_place_listener, for moving object `object` (0-based, the scene's "objects"
 *  order): world = R(q) * local + position replaces its trajectory from the next propagation
 *  frame on. Since 0.7.0. */
DPC_API dpc_status dpc_engine_place_object(dpc_engine* engine, int object, const dpc_pose* pose);

/** Any thread. Listeners traced every propagation frame: the length of the scene's
 *  "listeners" array, or 1 for a scene with one "listener" (or built from dpc_scene_data).
 *  All of them share each frame's rays (docs/dynamic.md "Several listeners"); one of them, the
 *  selected listener, is heard through dpc_engine_process and read by the copy functions.
 *  0 for a NULL engine or one being destroyed. */
DPC_API int dpc_engine_listener_count(const dpc_engine* engine);

/** Any thread, wait-free, no allocation. Makes listener `listener` (0-based) the one
 *  dpc_engine_process plays and dpc_engine_copy_* read, from the next propagation frame on;
 *  the audio side crossfades to its impulse responses as to any new ones (its cache is already
 *  warm: every listener is traced every frame). Until the first call the scene's first
 *  listener is selected. Errors: DPC_ERR_INVALID_ARGUMENT (null engine or index out of range;
 *  dpc_last_error() says which), DPC_ERR_STATE (being destroyed). */
DPC_API dpc_status dpc_engine_select_listener(dpc_engine* engine, int listener);

/** Any thread. The selected listener (0-based); 0 for a null engine. */
DPC_API int dpc_engine_selected_listener(const dpc_engine* engine);

/** Any thread, wait-free, no allocation. Source `source` (0-based, scene order) jumped: a
 *  respawn, a cut, a teleport. The next propagation frame drops the cached paths of its
 *  source-listener pairs instead of averaging the old place with the new one, so the new
 *  place is heard at once (its first response is one frame's estimate, noisier than a warm
 *  cache's). Call it with or after dpc_engine_place_source. Errors: DPC_ERR_INVALID_ARGUMENT
 *  (null engine or index out of range; dpc_last_error() says which), DPC_ERR_STATE. */
DPC_API dpc_status dpc_engine_teleport_source(dpc_engine* engine, int source);

/** The same for listener `listener` (0-based): every pair of that listener starts over at the
 *  next frame. Call it with or after dpc_engine_place_listener. Any thread, wait-free, no
 *  allocation. Errors: DPC_ERR_INVALID_ARGUMENT (null engine or index out of range),
 *  DPC_ERR_STATE. */
DPC_API dpc_status dpc_engine_teleport_listener(dpc_engine* engine, int listener);

/** Any thread; no allocation. The listener yaw and pitch (degrees, as defined at the top of
 *  this header) of the quaternion q = (qx, qy, qz, qw) in glTF order, normalised here, which
 *  rotates the listener's rest pose (facing +x, +y up): its forward direction
 *  f = R(q) * (1, 0, 0) gives yaw = atan2(-f.z, f.x) and pitch = asin(f.y); roll about f is
 *  dropped. Straight up or down the yaw is undetermined (0 if f is exactly vertical). Errors:
 *  DPC_ERR_INVALID_ARGUMENT (NULL output, non-finite value or zero quaternion;
 *  dpc_last_error() says which). */
DPC_API dpc_status dpc_yaw_pitch_from_quaternion(float qx, float qy, float qz, float qw,
                                                 float* yaw_degrees, float* pitch_degrees);

/** Any thread; no allocation. As dpc_yaw_pitch_from_quaternion, with the roll the quaternion
 *  holds: the angle in degrees, within [-180, 180], by which R(q) * (0, 1, 0) is turned about f
 *  from the up direction of yaw and pitch alone, positive towards the listener's right (the
 *  right ear down). Straight up or down (f vertical) the yaw is 0 and the heading is in the
 *  roll. dpc_engine_set_listener_head_pose with the three angles gives the listener the
 *  quaternion's orientation. Errors as dpc_yaw_pitch_from_quaternion. Since 0.5.0. */
DPC_API dpc_status dpc_yaw_pitch_roll_from_quaternion(float qx, float qy, float qz, float qw,
                                                      float* yaw_degrees, float* pitch_degrees,
                                                      float* roll_degrees);

/* Setters of 0.2.0 to 0.6.0, kept (the growth rule removes nothing): each does what the
 * dpc_engine_place_* function of its entity does with the same checks and the same channel,
 * for a pose given as separate arguments, and names those arguments in its errors. Threads,
 * allocation and errors are those of dpc_engine_place_listener. */

/** Listener pose from yaw and pitch in degrees (roll 0): yaw within [-3600, 3600], pitch within
 *  [-90, 90], each coordinate within +-10^6 m (dpc_last_error() names x, y, z, yaw_degrees or
 *  pitch_degrees). */
DPC_API dpc_status dpc_engine_set_listener_pose(dpc_engine* engine, int listener, float x,
                                                float y, float z, float yaw_degrees,
                                                float pitch_degrees);

/** As dpc_engine_set_listener_pose, with the head's roll in degrees, within [-180, 180]
 *  (positive: the right ear down; errors name roll_degrees). Since 0.5.0. */
DPC_API dpc_status dpc_engine_set_listener_head_pose(dpc_engine* engine, int listener, float x,
                                                     float y, float z, float yaw_degrees,
                                                     float pitch_degrees, float roll_degrees);

/** A source's position alone (metres; its rotation keeps following its keyframes or the last
 *  dpc_engine_set_source_rotation). */
DPC_API dpc_status dpc_engine_set_source_position(dpc_engine* engine, int source, float x, float y,
                                                  float z);

/** A source's rotation alone, q = (qx, qy, qz, qw) (its position keeps following its
 *  trajectory or the last dpc_engine_set_source_position; errors name q). */
DPC_API dpc_status dpc_engine_set_source_rotation(dpc_engine* engine, int source, float qx,
                                                  float qy, float qz, float qw);

/** A moving object's pose as (x, y, z) metres and q = (qx, qy, qz, qw) (errors name x, y, z or
 *  q). */
DPC_API dpc_status dpc_engine_set_object_pose(dpc_engine* engine, int object, float x, float y,
                                              float z, float qx, float qy, float qz, float qw);

#ifdef __cplusplus
}
#endif
#endif /* DPC_DPC_POSES_H */

/* The values the bridge tests send, shared by the agnocast-side node (C++) and
 * the DDS peer built with idlc's C types, so each side checks what the other
 * sent field by field. */
#ifndef AGNOCAST_BRIDGE_TEST_PATTERN_H
#define AGNOCAST_BRIDGE_TEST_PATTERN_H

#include <stdint.h>

/* Twist number i: linear.x carries i, the others are derived from it. */
static inline double twist_linear_x(uint32_t i) { return (double)i; }
static inline double twist_linear_y(uint32_t i) { return (double)i * 0.5; }
static inline double twist_linear_z(uint32_t i) { return -(double)i; }
static inline double twist_angular_x(uint32_t i) { return 0.25 + (double)(i % 7); }
static inline double twist_angular_y(uint32_t i) { return (double)i * 2.0; }
static inline double twist_angular_z(uint32_t i) { return (double)i * 1e-3; }

/* PointCloud2 number i: x, y, z, intensity as float32, 16 bytes a point. */
#define CLOUD_POINT_STEP 16u
#define CLOUD_FRAME_ID "lidar_top"
#define CLOUD_NANOSEC 123456789u
static inline uint8_t cloud_byte(uint32_t i, uint32_t k) {
  return (uint8_t)((k * 31u + (k >> 8) + i) & 0xffu);
}
static const char* const cloud_field_names[4] = {"x", "y", "z", "intensity"};

#endif

/* A DDS program that knows nothing of agnocast: Cyclone DDS with the C types
 * idlc generates from ros2_messages.idl, as a ROS 2 node on another machine
 * would see the bridge's topics. The bridge tests use it as the far side.
 *
 *   dds-peer send-twist TOPIC COUNT RATE_HZ
 *   dds-peer recv-twist TOPIC COUNT TIMEOUT_S QUIET_S
 *   dds-peer send-cloud TOPIC BYTES COUNT
 *   dds-peer recv-cloud TOPIC BYTES COUNT TIMEOUT_S
 *
 * A sender waits until a reader matched (DDS_PEER_MATCH readers, if set), sends,
 * and waits for every acknowledgement. A receiver prints "@ready" once a writer matched, checks
 * every field of every sample, and (recv-twist) waits QUIET_S more seconds for
 * samples that should not come; it exits 0 only when each of COUNT messages
 * arrived exactly once with the values sent. */
#include <dds/dds.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bridge_test_pattern.h"
#include "ros2_messages.h"

static int fail(const char* what, dds_return_t code) {
  fprintf(stderr, "dds-peer: %s: %s\n", what, dds_strretcode(code));
  return 1;
}

static dds_time_t now(void) { return dds_time(); }

static dds_qos_t* reliable_qos(int32_t depth) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  if (depth > 0) {
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  } else {
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  }
  return qos;
}

/* Waits until DDS_PEER_MATCH (default 1) endpoints of the other kind matched. */
static int wait_matched(dds_entity_t entity, int writer, double timeout_s) {
  const char* wanted_text = getenv("DDS_PEER_MATCH");
  const uint32_t wanted = wanted_text ? (uint32_t)atoi(wanted_text) : 1;
  const dds_time_t deadline = now() + (dds_time_t)(timeout_s * 1e9);
  while (now() < deadline) {
    uint32_t count = 0;
    if (writer) {
      dds_publication_matched_status_t status;
      if (dds_get_publication_matched_status(entity, &status) == 0) count = status.current_count;
    } else {
      dds_subscription_matched_status_t status;
      if (dds_get_subscription_matched_status(entity, &status) == 0) count = status.current_count;
    }
    if (count >= wanted) return 0;
    dds_sleepfor(DDS_MSECS(20));
  }
  fprintf(stderr, "dds-peer: nothing matched within %.0f s\n", timeout_s);
  return 1;
}

static dds_entity_t make_endpoint(dds_entity_t participant, const char* topic_name,
                                  const dds_topic_descriptor_t* descriptor, int writer,
                                  int32_t depth) {
  const dds_entity_t topic = dds_create_topic(participant, descriptor, topic_name, NULL, NULL);
  if (topic < 0) return topic;
  dds_qos_t* qos = reliable_qos(depth);
  const dds_entity_t entity = writer ? dds_create_writer(participant, topic, qos, NULL)
                                     : dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  return entity;
}

static int twist_matches(const geometry_msgs_msg_dds__Twist_* t, uint32_t i) {
  return t->linear.x == twist_linear_x(i) && t->linear.y == twist_linear_y(i) &&
         t->linear.z == twist_linear_z(i) && t->angular.x == twist_angular_x(i) &&
         t->angular.y == twist_angular_y(i) && t->angular.z == twist_angular_z(i);
}

static int send_twist(dds_entity_t participant, const char* topic, uint32_t count, double rate) {
  const dds_entity_t writer =
      make_endpoint(participant, topic, &geometry_msgs_msg_dds__Twist__desc, 1, 0);
  if (writer < 0) return fail("writer", writer);
  if (wait_matched(writer, 1, 60)) return 1;
  const dds_duration_t period = (dds_duration_t)(1e9 / rate);
  dds_time_t next = now();
  for (uint32_t i = 0; i < count; i++) {
    geometry_msgs_msg_dds__Twist_ t = {
        {twist_linear_x(i), twist_linear_y(i), twist_linear_z(i)},
        {twist_angular_x(i), twist_angular_y(i), twist_angular_z(i)}};
    const dds_return_t rc = dds_write(writer, &t);
    if (rc < 0) return fail("write", rc);
    next += period;
    const dds_time_t wait = next - now();
    if (wait > 0) dds_sleepfor(wait);
  }
  const dds_return_t acked = dds_wait_for_acks(writer, DDS_SECS(60));
  if (acked < 0) return fail("wait for acknowledgements", acked);
  printf("dds-peer: sent %u Twist on %s\n", count, topic);
  return 0;
}

static int recv_twist(dds_entity_t participant, const char* topic, uint32_t count, double timeout_s,
                      double quiet_s) {
  const dds_entity_t reader =
      make_endpoint(participant, topic, &geometry_msgs_msg_dds__Twist__desc, 0, 0);
  if (reader < 0) return fail("reader", reader);
  if (wait_matched(reader, 0, 60)) return 1;
  printf("@ready\n");
  fflush(stdout);
  unsigned char* seen = calloc(count, 1);
  uint32_t distinct = 0, duplicates = 0, wrong = 0, extra = 0;
  const dds_time_t deadline = now() + (dds_time_t)(timeout_s * 1e9);
  dds_time_t quiet_until = 0;
  for (;;) {
    const dds_time_t t = now();
    if (quiet_until == 0 && distinct == count) quiet_until = t + (dds_time_t)(quiet_s * 1e9);
    if ((quiet_until != 0 && t >= quiet_until) || (quiet_until == 0 && t >= deadline)) break;
    void* samples[64] = {0};
    dds_sample_info_t infos[64];
    const dds_return_t n = dds_take(reader, samples, infos, 64, 64);
    if (n < 0) return fail("take", n);
    for (dds_return_t k = 0; k < n; k++) {
      if (!infos[k].valid_data) continue;
      const geometry_msgs_msg_dds__Twist_* msg = samples[k];
      const double x = msg->linear.x;
      const uint32_t i = (uint32_t)x;
      if (x < 0 || (double)i != x || i >= count) {
        extra++;
      } else if (!twist_matches(msg, i)) {
        wrong++;
      } else if (seen[i]) {
        duplicates++;
      } else {
        seen[i] = 1;
        distinct++;
      }
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    if (n == 0) dds_sleepfor(DDS_MSECS(5));
  }
  printf("dds-peer: %s: %u of %u Twist, %u duplicates, %u with wrong values, %u unexpected\n",
         topic, distinct, count, duplicates, wrong, extra);
  free(seen);
  return distinct == count && duplicates == 0 && wrong == 0 && extra == 0 ? 0 : 1;
}

static void fill_cloud(sensor_msgs_msg_dds__PointCloud2_* cloud, uint32_t i, uint32_t bytes) {
  static sensor_msgs_msg_dds__PointField_ fields[4];
  for (uint32_t f = 0; f < 4; f++) {
    fields[f].name = (char*)cloud_field_names[f];
    fields[f].offset = 4 * f;
    fields[f].datatype = 7; /* FLOAT32 */
    fields[f].count = 1;
  }
  memset(cloud, 0, sizeof *cloud);
  cloud->header.stamp.sec = (int32_t)i;
  cloud->header.stamp.nanosec = CLOUD_NANOSEC;
  cloud->header.frame_id = (char*)CLOUD_FRAME_ID;
  cloud->height = 1;
  cloud->width = bytes / CLOUD_POINT_STEP;
  cloud->fields._buffer = fields;
  cloud->fields._length = cloud->fields._maximum = 4;
  cloud->is_bigendian = false;
  cloud->point_step = CLOUD_POINT_STEP;
  cloud->row_step = bytes;
  cloud->data._buffer = malloc(bytes);
  cloud->data._length = cloud->data._maximum = bytes;
  for (uint32_t k = 0; k < bytes; k++) cloud->data._buffer[k] = cloud_byte(i, k);
  cloud->is_dense = true;
}

static int cloud_matches(const sensor_msgs_msg_dds__PointCloud2_* c, uint32_t bytes) {
  const uint32_t i = (uint32_t)c->header.stamp.sec;
  if (c->header.stamp.nanosec != CLOUD_NANOSEC || strcmp(c->header.frame_id, CLOUD_FRAME_ID) ||
      c->height != 1 || c->width != bytes / CLOUD_POINT_STEP || c->fields._length != 4 ||
      c->is_bigendian || c->point_step != CLOUD_POINT_STEP || c->row_step != bytes ||
      c->data._length != bytes || !c->is_dense) {
    return 0;
  }
  for (uint32_t f = 0; f < 4; f++) {
    const sensor_msgs_msg_dds__PointField_* field = &c->fields._buffer[f];
    if (strcmp(field->name, cloud_field_names[f]) || field->offset != 4 * f ||
        field->datatype != 7 || field->count != 1) {
      return 0;
    }
  }
  for (uint32_t k = 0; k < bytes; k++) {
    if (c->data._buffer[k] != cloud_byte(i, k)) return 0;
  }
  return 1;
}

static int send_cloud(dds_entity_t participant, const char* topic, uint32_t bytes, uint32_t count) {
  const dds_entity_t writer =
      make_endpoint(participant, topic, &sensor_msgs_msg_dds__PointCloud2__desc, 1, 0);
  if (writer < 0) return fail("writer", writer);
  if (wait_matched(writer, 1, 60)) return 1;
  for (uint32_t i = 0; i < count; i++) {
    sensor_msgs_msg_dds__PointCloud2_ cloud;
    fill_cloud(&cloud, i, bytes);
    const dds_return_t rc = dds_write(writer, &cloud);
    free(cloud.data._buffer);
    if (rc < 0) return fail("write", rc);
  }
  const dds_return_t acked = dds_wait_for_acks(writer, DDS_SECS(120));
  if (acked < 0) return fail("wait for acknowledgements", acked);
  printf("dds-peer: sent %u PointCloud2 of %u bytes on %s\n", count, bytes, topic);
  return 0;
}

static int recv_cloud(dds_entity_t participant, const char* topic, uint32_t bytes, uint32_t count,
                      double timeout_s) {
  const dds_entity_t reader =
      make_endpoint(participant, topic, &sensor_msgs_msg_dds__PointCloud2__desc, 0, (int32_t)count);
  if (reader < 0) return fail("reader", reader);
  if (wait_matched(reader, 0, 60)) return 1;
  printf("@ready\n");
  fflush(stdout);
  uint32_t intact = 0, damaged = 0;
  const dds_time_t deadline = now() + (dds_time_t)(timeout_s * 1e9);
  while (intact + damaged < count && now() < deadline) {
    void* samples[1] = {0};
    dds_sample_info_t info;
    const dds_return_t n = dds_take(reader, samples, &info, 1, 1);
    if (n < 0) return fail("take", n);
    if (n == 0) {
      dds_sleepfor(DDS_MSECS(10));
      continue;
    }
    if (info.valid_data) {
      if (cloud_matches(samples[0], bytes)) {
        intact++;
      } else {
        damaged++;
      }
    }
    dds_return_loan(reader, samples, n);
  }
  printf("dds-peer: %s: %u of %u PointCloud2 of %u bytes intact, %u damaged\n", topic, intact,
         count, bytes, damaged);
  return intact == count && damaged == 0 ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: dds-peer send-twist|recv-twist|send-cloud|recv-cloud TOPIC ...\n");
    return 2;
  }
  const char* command = argv[1];
  const char* topic = argv[2];
  const dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
  if (participant < 0) return fail("participant", participant);
  int rc = 2;
  if (!strcmp(command, "send-twist") && argc == 5) {
    rc = send_twist(participant, topic, (uint32_t)atoi(argv[3]), atof(argv[4]));
  } else if (!strcmp(command, "recv-twist") && argc == 6) {
    rc = recv_twist(participant, topic, (uint32_t)atoi(argv[3]), atof(argv[4]), atof(argv[5]));
  } else if (!strcmp(command, "send-cloud") && argc == 5) {
    rc = send_cloud(participant, topic, (uint32_t)atoi(argv[3]), (uint32_t)atoi(argv[4]));
  } else if (!strcmp(command, "recv-cloud") && argc == 6) {
    rc = recv_cloud(participant, topic, (uint32_t)atoi(argv[3]), (uint32_t)atoi(argv[4]),
                    atof(argv[5]));
  } else {
    fprintf(stderr, "dds-peer: bad arguments for %s\n", command);
  }
  dds_delete(participant);
  return rc;
}

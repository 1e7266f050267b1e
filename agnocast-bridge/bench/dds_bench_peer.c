/* The DDS side of the bridge benchmark, on Cyclone DDS with idlc's C types
 * (PointCloud2_ whose data holds the payload), run in the other network
 * namespace or as the DDS-only baseline:
 *
 *   agnocast-bridge-bench-peer echo IN OUT SECONDS       writes back every sample of IN on OUT
 *   agnocast-bridge-bench-peer ping OUT IN BYTES COUNT   round trips through an echo: DDS alone
 *   agnocast-bridge-bench-peer flood OUT BYTES SECONDS   writes as fast as reliable DDS allows
 *   agnocast-bridge-bench-peer count IN SECONDS          prints what arrived per second
 *
 * Latency lines: "rtt BYTES n N median_us M p90_us P p99_us Q";
 * throughput lines: "received BYTES msgs N seconds S msg_per_s R MiB_per_s B". */
#include <dds/dds.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ros2_messages.h"

typedef sensor_msgs_msg_dds__PointCloud2_ Cloud;

static int fail(const char* what, dds_return_t code) {
  fprintf(stderr, "agnocast-bridge-bench-peer: %s: %s\n", what, dds_strretcode(code));
  return 1;
}

static dds_entity_t endpoint(dds_entity_t participant, const char* name, int writer) {
  const dds_entity_t topic =
      dds_create_topic(participant, &sensor_msgs_msg_dds__PointCloud2__desc, name, NULL, NULL);
  if (topic < 0) return topic;
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 16);
  const dds_entity_t entity = writer ? dds_create_writer(participant, topic, qos, NULL)
                                     : dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  return entity;
}

static void wait_matched(dds_entity_t writer) {
  for (int i = 0; i < 3000; i++) {
    dds_publication_matched_status_t status;
    if (dds_get_publication_matched_status(writer, &status) == 0 && status.current_count > 0)
      return;
    dds_sleepfor(DDS_MSECS(10));
  }
}

static Cloud make_cloud(uint32_t bytes) {
  Cloud cloud;
  memset(&cloud, 0, sizeof cloud);
  cloud.header.frame_id = (char*)"";
  cloud.height = 1;
  cloud.width = bytes;
  cloud.point_step = 1;
  cloud.row_step = bytes;
  cloud.data._buffer = calloc(bytes ? bytes : 1, 1);
  cloud.data._length = cloud.data._maximum = bytes;
  return cloud;
}

static int compare_u64(const void* a, const void* b) {
  const uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
  return x < y ? -1 : x > y;
}

static int echo(dds_entity_t participant, const char* in, const char* out, double seconds) {
  const dds_entity_t reader = endpoint(participant, in, 0);
  const dds_entity_t writer = endpoint(participant, out, 1);
  if (reader < 0 || writer < 0) return fail("endpoints", reader < 0 ? reader : writer);
  const dds_entity_t waitset = dds_create_waitset(participant);
  dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
  dds_waitset_attach(waitset, reader, 0);
  const dds_time_t end = dds_time() + (dds_time_t)(seconds * 1e9);
  uint32_t echoed = 0;
  printf("@ready\n");
  fflush(stdout);
  while (dds_time() < end) {
    dds_waitset_wait(waitset, NULL, 0, DDS_MSECS(100));
    void* samples[16] = {0};
    dds_sample_info_t infos[16];
    const dds_return_t n = dds_take(reader, samples, infos, 16, 16);
    for (dds_return_t k = 0; k < n; k++) {
      if (infos[k].valid_data && dds_write(writer, samples[k]) == 0) echoed++;
    }
    if (n > 0) dds_return_loan(reader, samples, n);
  }
  printf("echoed %u\n", echoed);
  return 0;
}

static int ping(dds_entity_t participant, const char* out, const char* in, uint32_t bytes,
                uint32_t count) {
  const dds_entity_t writer = endpoint(participant, out, 1);
  const dds_entity_t reader = endpoint(participant, in, 0);
  if (reader < 0 || writer < 0) return fail("endpoints", reader < 0 ? reader : writer);
  wait_matched(writer);
  dds_sleepfor(DDS_MSECS(500));  // the echo's writer matches our reader too
  const dds_entity_t waitset = dds_create_waitset(participant);
  dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
  dds_waitset_attach(waitset, reader, 0);
  Cloud cloud = make_cloud(bytes);
  const uint32_t warmup = count / 10 + 1;
  uint64_t* rtt = calloc(count, sizeof *rtt);
  uint32_t measured = 0;
  for (uint32_t i = 0; i < count + warmup; i++) {
    cloud.header.stamp.sec = (int32_t)i;
    const dds_time_t sent = dds_time();
    if (dds_write(writer, &cloud) != 0) continue;
    int got = 0;
    while (!got && dds_time() - sent < DDS_SECS(5)) {
      dds_waitset_wait(waitset, NULL, 0, DDS_MSECS(100));
      void* samples[4] = {0};
      dds_sample_info_t infos[4];
      const dds_return_t n = dds_take(reader, samples, infos, 4, 4);
      for (dds_return_t k = 0; k < n; k++) {
        if (infos[k].valid_data && ((Cloud*)samples[k])->header.stamp.sec == (int32_t)i) got = 1;
      }
      if (n > 0) dds_return_loan(reader, samples, n);
    }
    if (got && i >= warmup) rtt[measured++] = (uint64_t)(dds_time() - sent);
  }
  qsort(rtt, measured, sizeof *rtt, compare_u64);
  if (measured == 0) return fail("ping", DDS_RETCODE_TIMEOUT);
  printf("rtt %u n %u median_us %.1f p90_us %.1f p99_us %.1f\n", bytes, measured,
         rtt[measured / 2] / 1e3, rtt[measured * 9 / 10] / 1e3, rtt[measured * 99 / 100] / 1e3);
  return 0;
}

static int flood(dds_entity_t participant, const char* out, uint32_t bytes, double seconds) {
  const dds_entity_t writer = endpoint(participant, out, 1);
  if (writer < 0) return fail("writer", writer);
  wait_matched(writer);
  Cloud cloud = make_cloud(bytes);
  const dds_time_t end = dds_time() + (dds_time_t)(seconds * 1e9);
  uint32_t sent = 0;
  while (dds_time() < end) {
    cloud.header.stamp.sec = (int32_t)sent;
    if (dds_write(writer, &cloud) == 0) sent++;
  }
  printf("sent %u %u\n", bytes, sent);
  return 0;
}

static int count_samples(dds_entity_t participant, const char* in, double seconds) {
  const dds_entity_t reader = endpoint(participant, in, 0);
  if (reader < 0) return fail("reader", reader);
  const dds_entity_t waitset = dds_create_waitset(participant);
  dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
  dds_waitset_attach(waitset, reader, 0);
  printf("@ready\n");
  fflush(stdout);
  uint64_t messages = 0, bytes = 0;
  const dds_time_t start = dds_time();
  dds_time_t first = 0, last = 0, end = 0;
  for (;;) {
    const dds_time_t t = dds_time();
    if (end != 0 && t >= end) break;
    if (first == 0 && t - start > DDS_SECS(120)) break;
    dds_waitset_wait(waitset, NULL, 0, DDS_MSECS(100));
    void* samples[16] = {0};
    dds_sample_info_t infos[16];
    const dds_return_t n = dds_take(reader, samples, infos, 16, 16);
    for (dds_return_t k = 0; k < n; k++) {
      if (!infos[k].valid_data) continue;
      // The clock starts with the first sample and does not count it.
      if (first == 0) {
        first = dds_time();
        end = first + (dds_time_t)(seconds * 1e9);
        continue;
      }
      messages++;
      bytes += ((Cloud*)samples[k])->data._length;
      last = dds_time();
    }
    if (n > 0) dds_return_loan(reader, samples, n);
  }
  const double span = first != 0 && last > first ? (last - first) / 1e9 : 0;
  const uint32_t size = messages ? (uint32_t)(bytes / messages) : 0;
  printf("received %u msgs %llu seconds %.2f msg_per_s %.1f MiB_per_s %.2f\n", size,
         (unsigned long long)messages, span, span > 0 ? messages / span : 0,
         span > 0 ? bytes / span / 1048576.0 : 0);
  return 0;
}

int main(int argc, char** argv) {
  const dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
  if (participant < 0) return fail("participant", participant);
  int rc = 2;
  if (argc == 5 && !strcmp(argv[1], "echo")) {
    rc = echo(participant, argv[2], argv[3], atof(argv[4]));
  } else if (argc == 6 && !strcmp(argv[1], "ping")) {
    rc = ping(participant, argv[2], argv[3], (uint32_t)atoi(argv[4]), (uint32_t)atoi(argv[5]));
  } else if (argc == 5 && !strcmp(argv[1], "flood")) {
    rc = flood(participant, argv[2], (uint32_t)atoi(argv[3]), atof(argv[4]));
  } else if (argc == 4 && !strcmp(argv[1], "count")) {
    rc = count_samples(participant, argv[2], atof(argv[3]));
  } else {
    fprintf(stderr, "usage: agnocast-bridge-bench-peer echo|ping|flood|count ...\n");
  }
  dds_delete(participant);
  return rc;
}

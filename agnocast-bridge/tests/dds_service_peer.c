/* A DDS program that knows nothing of agnocast and plays a ROS 2 node on
 * rmw_cyclonedds_cpp for services: requests on rq/<name>Request, replies on
 * rr/<name>Reply, each with its 16-byte request header (the idlc types of
 * ros2_messages.idl carry it as two leading fields). The far side of the
 * bridge's service test.
 *
 *   dds-service-peer serve-add-two-ints SERVICE COUNT TIMEOUT_S DELAY_MS
 *   dds-service-peer call-set-bool SERVICE COUNT TIMEOUT_S
 *
 * serve-add-two-ints answers AddTwoInts (sum = a + b) with the request's
 * header, DELAY_MS after each request came; it prints "@ready" once its
 * reader and writer matched the bridge's and exits 0 after COUNT answers.
 * call-set-bool sends COUNT SetBool requests (data alternating, from true),
 * with its own writer's instance handle and sequence numbers 1..COUNT, and
 * exits 0 when each got exactly one reply naming it, with success equal to
 * the data sent and the message "set to true" or "set to false". */
#include <dds/dds.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ros2_messages.h"

static int fail(const char* what, dds_return_t code) {
  fprintf(stderr, "dds-service-peer: %s: %s\n", what, dds_strretcode(code));
  return 1;
}

struct endpoints {
  dds_entity_t reader;
  dds_entity_t writer;
};

/* A service's (serving) or a client's reader and writer, with the USER_DATA
 * rmw_cyclonedds_cpp gives them. */
static int make_endpoints(dds_entity_t participant, const char* service, int serving,
                          struct endpoints* out) {
  char request_name[256], reply_name[256];
  snprintf(request_name, sizeof request_name, "rq%sRequest", service);
  snprintf(reply_name, sizeof reply_name, "rr%sReply", service);
  const dds_topic_descriptor_t* request_type =
      serving ? &example_interfaces_srv_dds__AddTwoInts_Request__desc
              : &std_srvs_srv_dds__SetBool_Request__desc;
  const dds_topic_descriptor_t* reply_type =
      serving ? &example_interfaces_srv_dds__AddTwoInts_Response__desc
              : &std_srvs_srv_dds__SetBool_Response__desc;
  const dds_entity_t request_topic =
      dds_create_topic(participant, request_type, request_name, NULL, NULL);
  if (request_topic < 0) return fail("request topic", request_topic);
  const dds_entity_t reply_topic =
      dds_create_topic(participant, reply_type, reply_name, NULL, NULL);
  if (reply_topic < 0) return fail("reply topic", reply_topic);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 100);
  const char* user_data = serving ? "serviceid=01.02.03.04.05.06.07.08.09.0a.0b.0c.00.00.00.01;"
                                  : "clientid=01.02.03.04.05.06.07.08.09.0a.0b.0c.00.00.00.02;";
  dds_qset_userdata(qos, user_data, strlen(user_data));
  out->reader = dds_create_reader(participant, serving ? request_topic : reply_topic, qos, NULL);
  out->writer = dds_create_writer(participant, serving ? reply_topic : request_topic, qos, NULL);
  dds_delete_qos(qos);
  if (out->reader < 0) return fail("reader", out->reader);
  if (out->writer < 0) return fail("writer", out->writer);
  return 0;
}

static int wait_matched(const struct endpoints* e, double timeout_s) {
  const dds_time_t deadline = dds_time() + (dds_time_t)(timeout_s * 1e9);
  while (dds_time() < deadline) {
    dds_publication_matched_status_t writer;
    dds_subscription_matched_status_t reader;
    if (dds_get_publication_matched_status(e->writer, &writer) == 0 &&
        dds_get_subscription_matched_status(e->reader, &reader) == 0 && writer.current_count > 0 &&
        reader.current_count > 0) {
      return 0;
    }
    dds_sleepfor(DDS_MSECS(20));
  }
  fprintf(stderr, "dds-service-peer: the bridge's endpoints did not match within %.0f s\n",
          timeout_s);
  return 1;
}

static int serve_add_two_ints(dds_entity_t participant, const char* service, uint32_t count,
                              double timeout_s, uint32_t delay_ms) {
  struct endpoints e;
  if (make_endpoints(participant, service, 1, &e) || wait_matched(&e, 60)) return 1;
  printf("@ready\n");
  fflush(stdout);
  uint32_t answered = 0;
  const dds_time_t deadline = dds_time() + (dds_time_t)(timeout_s * 1e9);
  while (answered < count && dds_time() < deadline) {
    void* samples[1] = {0};
    dds_sample_info_t info;
    const dds_return_t n = dds_take(e.reader, samples, &info, 1, 1);
    if (n < 0) return fail("take", n);
    if (n == 0) {
      dds_sleepfor(DDS_MSECS(5));
      continue;
    }
    if (info.valid_data) {
      const example_interfaces_srv_dds__AddTwoInts_Request_* request = samples[0];
      example_interfaces_srv_dds__AddTwoInts_Response_ response;
      response.client = request->client;
      response.sequence_number = request->sequence_number;
      response.sum = request->a + request->b;
      if (delay_ms > 0) dds_sleepfor(DDS_MSECS(delay_ms));
      const dds_return_t rc = dds_write(e.writer, &response);
      if (rc < 0) return fail("write", rc);
      answered++;
    }
    dds_return_loan(e.reader, samples, n);
  }
  dds_wait_for_acks(e.writer, DDS_SECS(10));
  printf("dds-service-peer: %s: answered %u of %u\n", service, answered, count);
  return answered == count ? 0 : 1;
}

static int call_set_bool(dds_entity_t participant, const char* service, uint32_t count,
                         double timeout_s) {
  struct endpoints e;
  if (make_endpoints(participant, service, 0, &e) || wait_matched(&e, 60)) return 1;
  dds_instance_handle_t self = 0;
  const dds_return_t handle = dds_get_instance_handle(e.writer, &self);
  if (handle < 0) return fail("writer instance handle", handle);
  for (uint32_t i = 0; i < count; i++) {
    std_srvs_srv_dds__SetBool_Request_ request;
    request.client = self;
    request.sequence_number = (int64_t)i + 1;
    request.data = i % 2 == 0;
    const dds_return_t rc = dds_write(e.writer, &request);
    if (rc < 0) return fail("write", rc);
  }
  unsigned char* seen = calloc(count, 1);
  uint32_t good = 0, bad = 0;
  const dds_time_t deadline = dds_time() + (dds_time_t)(timeout_s * 1e9);
  while (good + bad < count && dds_time() < deadline) {
    void* samples[1] = {0};
    dds_sample_info_t info;
    const dds_return_t n = dds_take(e.reader, samples, &info, 1, 1);
    if (n < 0) return fail("take", n);
    if (n == 0) {
      dds_sleepfor(DDS_MSECS(5));
      continue;
    }
    if (info.valid_data) {
      const std_srvs_srv_dds__SetBool_Response_* reply = samples[0];
      const int64_t i = reply->sequence_number - 1;
      const int data = i % 2 == 0;
      if (reply->client != self || i < 0 || i >= (int64_t)count || seen[i] ||
          reply->success != data || strcmp(reply->message, data ? "set to true" : "set to false")) {
        fprintf(stderr, "dds-service-peer: a bad reply: client %llx sequence %lld success %d\n",
                (unsigned long long)reply->client, (long long)reply->sequence_number,
                reply->success);
        bad++;
      } else {
        seen[i] = 1;
        good++;
      }
    }
    dds_return_loan(e.reader, samples, n);
  }
  free(seen);
  printf("dds-service-peer: %s: %u of %u replies right, %u wrong\n", service, good, count, bad);
  return good == count && bad == 0 ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: dds-service-peer serve-add-two-ints|call-set-bool SERVICE ...\n");
    return 2;
  }
  const char* command = argv[1];
  const char* service = argv[2];
  const dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
  if (participant < 0) return fail("participant", participant);
  int rc = 2;
  if (!strcmp(command, "serve-add-two-ints") && argc == 6) {
    rc = serve_add_two_ints(participant, service, (uint32_t)atoi(argv[3]), atof(argv[4]),
                            (uint32_t)atoi(argv[5]));
  } else if (!strcmp(command, "call-set-bool") && argc == 5) {
    rc = call_set_bool(participant, service, (uint32_t)atoi(argv[3]), atof(argv[4]));
  } else {
    fprintf(stderr, "dds-service-peer: bad arguments for %s\n", command);
  }
  dds_delete(participant);
  return rc;
}

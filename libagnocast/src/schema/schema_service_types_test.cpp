#include "agnocast/schema_service_types.hpp"

#include <gtest/gtest.h>

#include <string>

#include "agnocast/errors.hpp"
#include "schema/schema_service_test_types.hpp"

namespace agnocast {
namespace {

using schema_service_test::Sum;

TEST(SchemaServiceTypes, BothPartsNameTheServiceType) {
  ServiceTypes types = service_types_of<Sum>("/sum");
  EXPECT_EQ(service_type_name(types), "schema_service_test/srv/Sum");
  types.response.type_name = "schema_service_test/srv/Other_Response";
  EXPECT_EQ(service_type_name(types), "");
  types.response.type_name = "schema_service_test/msg/Sum";
  EXPECT_EQ(service_type_name(types), "");
}

TEST(SchemaServiceTypes, TheTypeMayBeWrittenWithOrWithoutItsSrvFolder) {
  EXPECT_EQ(normalized_service_type("std_srvs/srv/SetBool"), "std_srvs/srv/SetBool");
  EXPECT_EQ(normalized_service_type("std_srvs/SetBool"), "std_srvs/srv/SetBool");
  for (const char* bad : {"", "SetBool", "/SetBool", "std_srvs/", "std_srvs/msg/SetBool",
                          "std_srvs/srv/", "a/srv/b/c"}) {
    EXPECT_EQ(normalized_service_type(bad), "") << bad;
  }
}

TEST(SchemaServiceTypes, AnotherTypeIsATypeMismatchNamingBoth) {
  const ServiceTypes types = service_types_of<Sum>("/sum");
  EXPECT_NO_THROW(require_service_type(types, "/sum", "schema_service_test/srv/Sum"));
  EXPECT_NO_THROW(require_service_type(types, "/sum", "schema_service_test/Sum"));
  try {
    require_service_type(types, "/sum", "std_srvs/SetBool");
    FAIL() << "another type was accepted";
  } catch (const TypeMismatch& error) {
    EXPECT_EQ(std::string(error.what()),
              "agnocast: service /sum has type schema_service_test/srv/Sum, not "
              "std_srvs/srv/SetBool; `agnocast-cli service type /sum` shows it");
  }
  EXPECT_THROW(require_service_type(types, "/sum", "no type"), TypeMismatch);
}

}  // namespace
}  // namespace agnocast

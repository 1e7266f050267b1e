#include "module_parameters.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "config.hpp"

namespace agnocastd {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

const DeclaredParameters agnocast_parameters = {{"pool_size", "ulong"},
                                                {"pool_count", "uint"},
                                                {"verbose", "bool"},
                                                {"offset", "int"},
                                                {"cpus", "array of int"}};

std::string error_of(const ParameterValues& configured) {
  try {
    check_module_parameters(configured, agnocast_parameters);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "";
}

TEST(ParseParameterTypes, ReadsModinfoParmtypeLines) {
  EXPECT_EQ(parse_parameter_types("pool_size:ulong\npool_count:uint\ncpus:array of int\n\n"),
            (DeclaredParameters{
                {"pool_size", "ulong"}, {"pool_count", "uint"}, {"cpus", "array of int"}}));
  EXPECT_THAT(parse_parameter_types(""), IsEmpty());
}

TEST(CheckModuleParameters, AcceptsWhatTheTypesTake) {
  EXPECT_EQ(error_of({{"pool_size", "67108864"},
                      {"pool_count", "0x40"},
                      {"verbose", "Y"},
                      {"offset", "-3"},
                      {"cpus", "1,2,-1"}}),
            "");
}

TEST(CheckModuleParameters, AnUnknownNameIsAnErrorNamingItAndTheDeclaredOnes) {
  EXPECT_EQ(error_of({{"pool_szie", "1"}}),
            "config key 'module_parameters.pool_szie': agnocast.ko has no parameter "
            "'pool_szie' (it declares: cpus, offset, pool_count, pool_size, verbose)");
}

TEST(CheckModuleParameters, AValueTheTypeCannotTakeIsAnError) {
  EXPECT_EQ(error_of({{"pool_count", "-1"}}),
            "config key 'module_parameters.pool_count': '-1' is not a valid uint");
  EXPECT_THAT(error_of({{"pool_count", "4294967296"}}), HasSubstr("not a valid uint"));
  EXPECT_THAT(error_of({{"pool_size", "64M"}}), HasSubstr("not a valid ulong"));
  EXPECT_THAT(error_of({{"verbose", "maybe"}}), HasSubstr("not a valid bool"));
  EXPECT_THAT(error_of({{"offset", "2147483648"}}), HasSubstr("not a valid int"));
  EXPECT_THAT(error_of({{"cpus", "1,x"}}), HasSubstr("not a valid array of int"));
}

TEST(CheckModuleParameters, OnlyNamesAreCheckedWhenTypesAreUnknown) {
  EXPECT_NO_THROW(check_module_parameters({{"pool_size", "64M"}}, {{"pool_size", ""}}));
  EXPECT_THROW(check_module_parameters({{"pool_szie", "1"}}, {{"pool_size", ""}}), ConfigError);
}

TEST(LoadedParameterDifferences, NamesEachDifferenceInTheKernelsSpelling) {
  const ParameterValues loaded = {
      {"pool_size", "67108864"}, {"pool_count", "64"}, {"verbose", "N"}};
  EXPECT_THAT(loaded_parameter_differences(
                  {{"pool_size", "0x4000000"}, {"pool_count", "16"}, {"verbose", "1"}},
                  agnocast_parameters, loaded),
              ElementsAre("agnocast.ko is already loaded with pool_count=64, not "
                          "module_parameters.pool_count=16: the configured value applies only "
                          "after the module is reloaded",
                          "agnocast.ko is already loaded with verbose=N, not "
                          "module_parameters.verbose=1: the configured value applies only after "
                          "the module is reloaded"));
  EXPECT_THAT(loaded_parameter_differences({{"pool_count", "64"}}, agnocast_parameters, loaded),
              IsEmpty());
}

}  // namespace
}  // namespace agnocastd

#include "agnocast/service_access.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "agnocast/naming.hpp"

namespace agnocast {
namespace {

using Kind = AccessPrincipal::Kind;
using Match = TopicPattern::Match;
using Principals = std::vector<AccessPrincipal>;

const Principals servers{{Kind::user, 1001}};
const Principals callers{{Kind::group, 2002}, {Kind::anyone, 0}};

TEST(ServicePattern, ParsesTheThreeKinds) {
  const struct {
    const char* text;
    const char* prefix;
    Match match;
  } cases[] = {
      {"/arm/enable", "/arm/enable", Match::exact},
      {"/arm/*", "/arm", Match::children},
      {"/arm/**", "/arm", Match::descendants},
      {"/*", "", Match::children},
      {"/**", "", Match::descendants},
  };
  for (const auto& c : cases) {
    const TopicPattern pattern = parse_service_pattern(c.text);
    EXPECT_EQ(pattern.prefix, c.prefix) << c.text;
    EXPECT_EQ(pattern.match, c.match) << c.text;
  }
}

TEST(ServicePattern, RejectsBadAndReservedNamesNamingThePattern) {
  const std::string too_long = "/" + std::string(service_name_max, 'a');
  for (const std::string& text :
       std::vector<std::string>{"", "arm", "arm/**", "/a/**/b", "/a*", "/a/***", "**", "*", "/",
                                "/a/", "/a//**", "/_service_request/**", "/_service_reply/x",
                                "/_service_request", "/a b", "/a\n", too_long, too_long + "/**"}) {
    try {
      parse_service_pattern(text);
      ADD_FAILURE() << "accepted '" << text << "'";
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      EXPECT_EQ(message.rfind("access rule services '" + text + "': ", 0), 0u) << message;
      EXPECT_NE(message.find("/**"), std::string::npos) << message;
    }
  }
  // what() ends at a NUL, so only the refusal is checked.
  EXPECT_THROW(parse_service_pattern(std::string("/a\0b", 4)), std::invalid_argument);
  EXPECT_NO_THROW(parse_service_pattern("/" + std::string(service_name_max - 1, 'a') + "/**"));
}

TEST(ServiceRule, ServeAndCallBecomeTopicRightsOnRequestThenReplyTopics) {
  const auto rules = topic_rules_of({"/arm/*", servers, callers});
  EXPECT_EQ(rules[0], (AccessRule{"/_service_request/arm/*", callers, servers}));
  EXPECT_EQ(rules[1], (AccessRule{"/_service_reply/arm/*", servers, callers}));
  EXPECT_EQ(topic_rules_of({"/arm/enable", servers, std::nullopt})[0],
            (AccessRule{"/_service_request/arm/enable", std::nullopt, servers}));
  EXPECT_EQ(topic_rules_of({"/arm/**", std::nullopt, Principals{}})[1],
            (AccessRule{"/_service_reply/arm/**", std::nullopt, Principals{}}));
  EXPECT_THROW(topic_rules_of({"/_service_reply/x", servers, callers}), std::invalid_argument);
}

TEST(ServiceRule, EveryServiceCoversTheCarriersOfEveryServiceAndNothingElse) {
  const auto rules = topic_rules_of({"/**", servers, callers});
  EXPECT_EQ(rules[0].topics, "/_service_request/**");
  EXPECT_EQ(rules[1].topics, "/_service_reply/**");
  const TopicPattern request = parse_topic_pattern(rules[0].topics);
  EXPECT_TRUE(matches(request, "/_service_request/arm/enable"));
  EXPECT_TRUE(matches(request, "/_service_request/x"));
  EXPECT_FALSE(matches(request, "/_service_reply/x"));
  EXPECT_FALSE(matches(request, "/_service_requests/x"));
  EXPECT_FALSE(matches(request, "/chatter"));
  const TopicPattern top = parse_topic_pattern(topic_rules_of({"/*", servers, callers})[1].topics);
  EXPECT_TRUE(matches(top, "/_service_reply/x"));
  EXPECT_FALSE(matches(top, "/_service_reply/x/y"));
}

TEST(ServiceRule, TheCarriersOfTheLongestServiceNameFitATopicName) {
  const std::string longest = "/" + std::string(service_name_max - 1, 'a');
  for (const AccessRule& rule : topic_rules_of({longest + "/**", servers, callers})) {
    EXPECT_EQ(topic_name_problem(parse_topic_pattern(rule.topics).prefix), "");
  }
}

TEST(WrittenRules, PairsBecomeServiceRulesInPlace) {
  const ServiceAccessRule arm{"/arm/*", servers, callers};
  const ServiceAccessRule all{"/**", std::nullopt, Principals{}};
  const AccessRule chatter{"/chatter", callers, std::nullopt};
  const AccessRule everything{"/**", servers, servers};
  std::vector<AccessRule> rules{chatter};
  for (const AccessRule& rule : topic_rules_of(arm)) rules.push_back(rule);
  rules.push_back(everything);
  for (const AccessRule& rule : topic_rules_of(all)) rules.push_back(rule);
  EXPECT_EQ(written_access_rules(rules),
            (std::vector<WrittenAccessRule>{chatter, arm, everything, all}));
}

TEST(WrittenRules, RulesThatNoServiceRuleMakesStayTopicRules) {
  const auto pair = topic_rules_of({"/arm/*", servers, callers});
  const AccessRule other_reply{"/_service_reply/leg/*", servers, callers};
  const AccessRule swapped{pair[1].topics, callers, servers};
  const AccessRule reserved{"/_service_request/**", servers, callers};
  const AccessRule bare{"/_service_request", callers, servers};
  const AccessRule look_alike{"/_service_requests/a", callers, servers};
  const AccessRule look_alike_reply{"/_service_replys/a", servers, callers};
  for (const std::vector<AccessRule>& rules : {std::vector<AccessRule>{pair[0]},
                                               {pair[1], pair[0]},
                                               {pair[0], other_reply},
                                               {pair[0], swapped},
                                               {reserved},
                                               {bare, pair[1]},
                                               {look_alike, look_alike_reply}}) {
    const std::vector<WrittenAccessRule> written = written_access_rules(rules);
    ASSERT_EQ(written.size(), rules.size());
    for (std::size_t i = 0; i < rules.size(); ++i) {
      EXPECT_EQ(written[i], WrittenAccessRule{rules[i]}) << rules[i].topics;
    }
  }
  // A lone request rule, then a whole pair: the pair is still found.
  const std::vector<WrittenAccessRule> written = written_access_rules({pair[0], pair[0], pair[1]});
  ASSERT_EQ(written.size(), 2u);
  EXPECT_EQ(written[1], WrittenAccessRule{(ServiceAccessRule{"/arm/*", servers, callers})});
}

}  // namespace
}  // namespace agnocast

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "agnocast/access_policy.hpp"

namespace agnocast {
namespace {

using Match = TopicPattern::Match;

TEST(TopicPattern, ParsesTheThreeKindsAndRoundTrips) {
  const struct {
    const char* text;
    const char* prefix;
    Match match;
  } cases[] = {
      {"/chatter", "/chatter", Match::exact},
      {"/safety/**", "/safety", Match::descendants},
      {"/sensing/lidar/*", "/sensing/lidar", Match::children},
      {"/**", "", Match::descendants},
      {"/*", "", Match::children},
  };
  for (const auto& c : cases) {
    const TopicPattern pattern = parse_topic_pattern(c.text);
    EXPECT_EQ(pattern.prefix, c.prefix) << c.text;
    EXPECT_EQ(pattern.match, c.match) << c.text;
    EXPECT_EQ(to_string(pattern), c.text);
  }
}

TEST(TopicPattern, RejectsWhatIsNotANameWithAnOptionalWildcardEnd) {
  for (const char* text :
       {"", "chatter", "safety/**", "/a/**/b", "/a*", "/a/***", "**", "*", "/a/", "/a//**", "/"}) {
    try {
      parse_topic_pattern(text);
      ADD_FAILURE() << "accepted '" << text << "'";
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(std::string("'") + text + "'"), std::string::npos) << message;
      EXPECT_NE(message.find("/**"), std::string::npos) << message;
    }
  }
}

TEST(TopicPattern, ExactMatchesOnlyItself) {
  const TopicPattern pattern = parse_topic_pattern("/a/b");
  EXPECT_TRUE(matches(pattern, "/a/b"));
  EXPECT_FALSE(matches(pattern, "/a"));
  EXPECT_FALSE(matches(pattern, "/a/b/c"));
  EXPECT_FALSE(matches(pattern, "/a/bc"));
}

TEST(TopicPattern, ChildrenMatchExactlyOneMoreLevel) {
  const TopicPattern pattern = parse_topic_pattern("/a/*");
  EXPECT_TRUE(matches(pattern, "/a/b"));
  EXPECT_FALSE(matches(pattern, "/a"));
  EXPECT_FALSE(matches(pattern, "/a/b/c"));
  EXPECT_FALSE(matches(pattern, "/ab"));
  EXPECT_FALSE(matches(pattern, "/ab/c"));
  const TopicPattern top = parse_topic_pattern("/*");
  EXPECT_TRUE(matches(top, "/a"));
  EXPECT_FALSE(matches(top, "/a/b"));
}

TEST(TopicPattern, DescendantsMatchAnyDepthBelowButNotThePrefix) {
  const TopicPattern pattern = parse_topic_pattern("/safety/**");
  EXPECT_TRUE(matches(pattern, "/safety/brake"));
  EXPECT_TRUE(matches(pattern, "/safety/brake/front/left"));
  EXPECT_FALSE(matches(pattern, "/safety"));
  EXPECT_FALSE(matches(pattern, "/safetyx/brake"));
  EXPECT_FALSE(matches(pattern, "/other/safety/brake"));
  const TopicPattern everything = parse_topic_pattern("/**");
  EXPECT_TRUE(matches(everything, "/a"));
  EXPECT_TRUE(matches(everything, "/a/b/c"));
}

TEST(TopicPattern, CoversWhatItMatchesAll) {
  const auto covers_text = [](const char* outer, const char* inner) {
    return covers(parse_topic_pattern(outer), parse_topic_pattern(inner));
  };
  for (const char* inner : {"/a", "/a/b/c", "/*", "/**", "/a/*", "/a/**"}) {
    EXPECT_TRUE(covers_text("/**", inner)) << inner;
    EXPECT_TRUE(covers_text(inner, inner)) << inner;
  }
  EXPECT_TRUE(covers_text("/a/**", "/a/b"));
  EXPECT_TRUE(covers_text("/a/**", "/a/b/*"));
  EXPECT_TRUE(covers_text("/a/**", "/a/b/**"));
  EXPECT_TRUE(covers_text("/a/**", "/a/*"));
  EXPECT_TRUE(covers_text("/a/*", "/a/b"));
  EXPECT_TRUE(covers_text("/*", "/a"));
  EXPECT_FALSE(covers_text("/a/**", "/a"));
  EXPECT_FALSE(covers_text("/a/**", "/ab/*"));
  EXPECT_FALSE(covers_text("/a/**", "/**"));
  EXPECT_FALSE(covers_text("/a/*", "/a/**"));
  EXPECT_FALSE(covers_text("/a/*", "/a/b/c"));
  EXPECT_FALSE(covers_text("/a/*", "/a/b/*"));
  EXPECT_FALSE(covers_text("/*", "/a/*"));
  EXPECT_FALSE(covers_text("/*", "/**"));
  EXPECT_FALSE(covers_text("/a", "/a/*"));
  EXPECT_FALSE(covers_text("/a", "/b"));
}

}  // namespace
}  // namespace agnocast

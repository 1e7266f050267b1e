// The topic patterns of access rules (<agnocast/access_policy.hpp>): pure
// functions of their text, apart from the device calls of access_policy.cpp,
// so that configuration checkers and the fuzz targets use them alone.
#include <stdexcept>

#include "agnocast/access_policy.hpp"
#include "agnocast/naming.hpp"

namespace agnocast {

TopicPattern parse_topic_pattern(std::string_view pattern) {
  TopicPattern parsed;
  std::string_view prefix = pattern;
  if (pattern.ends_with("/**")) {
    parsed.match = TopicPattern::Match::descendants;
    prefix.remove_suffix(3);
  } else if (pattern.ends_with("/*")) {
    parsed.match = TopicPattern::Match::children;
    prefix.remove_suffix(2);
  }
  if (prefix.empty() && parsed.match != TopicPattern::Match::exact) return parsed;
  if (const std::string problem = topic_name_problem(prefix); !problem.empty()) {
    throw std::invalid_argument("access rule topics '" + std::string(pattern) + "': " + problem +
                                " (a pattern is a topic name, optionally followed by /* for "
                                "one more level or /** for any depth)");
  }
  parsed.prefix = prefix;
  return parsed;
}

std::string to_string(const TopicPattern& pattern) {
  switch (pattern.match) {
    case TopicPattern::Match::children:
      return pattern.prefix + "/*";
    case TopicPattern::Match::descendants:
      return pattern.prefix + "/**";
    case TopicPattern::Match::exact:
      break;
  }
  return pattern.prefix;
}

bool matches(const TopicPattern& pattern, std::string_view topic) {
  if (pattern.match == TopicPattern::Match::exact) return topic == pattern.prefix;
  if (!topic.starts_with(pattern.prefix)) return false;
  topic.remove_prefix(pattern.prefix.size());
  if (topic.size() < 2 || topic.front() != '/') return false;
  topic.remove_prefix(1);
  return pattern.match == TopicPattern::Match::descendants ||
         topic.find('/') == std::string_view::npos;
}

bool covers(const TopicPattern& outer, const TopicPattern& inner) {
  if (inner.match == TopicPattern::Match::exact) return matches(outer, inner.prefix);
  switch (outer.match) {
    case TopicPattern::Match::children:
      return inner.match == TopicPattern::Match::children && inner.prefix == outer.prefix;
    case TopicPattern::Match::descendants:
      return inner.prefix == outer.prefix || matches(outer, inner.prefix);
    case TopicPattern::Match::exact:
      break;
  }
  return false;  // inner matches more than one topic
}

}  // namespace agnocast

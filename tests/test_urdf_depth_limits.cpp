// Two URDF refusals made before urdfdom reads the text (robot/urdf_check.hpp): elements nested
// deeper than kMaxElementDepth (a parser recursing per level would overflow its stack), at the line
// and column of the first element too deep; and <limit>s with lower > upper or lower = upper. A
// <limit> that omits lower or upper is no limit on that side (urdfdom alone would read 0).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "robot/urdf.hpp"
#include "robot/urdf_check.hpp"

using namespace ks;
using urdf_check::kMaxElementDepth;

namespace {

const Eigen::Vector3d kGravityY(0, -9.81, 0);

// Two revolute joints about z, 0.5 m links of 1 kg; `limit1` is joint j1's <limit> element, and
// `inside` is put inside link l2 (unknown elements: urdfdom ignores them).
std::string two_joints(const std::string& limit1, const std::string& inside = "") {
  std::ostringstream s;
  s << "<robot name=\"two\">\n  <link name=\"base\"/>\n";
  for (int i = 1; i <= 2; ++i) {
    s << "  <joint name=\"j" << i << "\" type=\"revolute\">\n    <parent link=\"" << (i == 1 ? "base" : "l1")
      << "\"/>\n    <child link=\"l" << i << "\"/>\n    <origin xyz=\"" << (i == 1 ? 0.0 : 0.5)
      << " 0 0\"/>\n    <axis xyz=\"0 0 1\"/>\n    "
      << (i == 1 ? limit1 : "<limit lower=\"-2\" upper=\"2\" effort=\"1\" velocity=\"1\"/>") << "\n  </joint>\n";
    s << "  <link name=\"l" << i << "\">\n    <inertial><origin xyz=\"0.25 0 0\"/><mass value=\"1\"/>"
      << "<inertia ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.02\"/></inertial>\n"
      << (i == 2 ? inside : "") << "  </link>\n";
  }
  s << "</robot>\n";
  return s.str();
}

const std::string kLimited = "<limit lower=\"-1\" upper=\"1.5\" effort=\"1\" velocity=\"1\"/>";

// `levels` nested <x> elements, each on its own line with two spaces (the outermost at depth 3:
// robot > link > x).
std::string nested(int levels) {
  std::string open, close;
  for (int k = 0; k < levels; ++k) open += "  <x>\n", close += "</x>";
  return open + close + "\n";
}

template <class F>
UrdfError expect_error(F f) {
  try {
    f();
  } catch (const UrdfError& e) {
    return e;
  }
  ADD_FAILURE() << "no UrdfError thrown";
  return UrdfError("", 0, "");
}

int line_of(const std::string& text, const std::string& needle) {
  const std::size_t pos = text.find(needle);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

}  // namespace

TEST(UrdfDepth, FortyThousandLevelsAreRefusedAtTheFirstTooDeep) {
  const std::string text = two_joints(kLimited, nested(40000));
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l2", kGravityY, "deep.urdf"); });
  // robot (1) > link (2) > the x elements from depth 3: the first too deep is x number max - 1
  const int first_x = line_of(text, "  <x>");
  EXPECT_EQ(e.line, first_x + kMaxElementDepth - 2);
  EXPECT_EQ(e.column, 3);  // after the two spaces
  EXPECT_NE(e.message.find("nested " + std::to_string(kMaxElementDepth + 1) + " elements deep"), std::string::npos)
      << e.message;
  EXPECT_NE(std::string(e.what()).find("deep.urdf:" + std::to_string(e.line) + ":3: "), std::string::npos) << e.what();
}

TEST(UrdfDepth, TheLimitItselfIsAccepted) {
  const Chain c = parse_urdf(two_joints(kLimited, nested(kMaxElementDepth - 2)), "base", "l2", kGravityY);
  EXPECT_EQ(c.dof(), 2);
  EXPECT_THROW(parse_urdf(two_joints(kLimited, nested(kMaxElementDepth - 1)), "base", "l2", kGravityY), UrdfError);
}

TEST(UrdfDepth, MarkupThatIsNotAnElementDoesNotCount) {
  // '<' in comments and CDATA, '>' in quoted values, empty elements: none nests
  std::string inside;
  for (int k = 0; k < 2 * kMaxElementDepth; ++k)
    inside += "<!-- <a> --><![CDATA[<b>]]><y note=\"a > b\"/><z t='>'></z>\n";
  const Chain c = parse_urdf(two_joints(kLimited, inside), "base", "l2", kGravityY);
  EXPECT_EQ(c.dof(), 2);
}

TEST(UrdfDepth, ColumnCountsCharactersNotBytes) {
  std::string deep;
  for (int k = 0; k < kMaxElementDepth; ++k) deep += "<x>";
  // two-byte characters before the element too deep on its line
  const std::string text = two_joints(kLimited, "<!-- \xc3\xa9\xc3\xa9 -->" + deep + "\n");
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l2", kGravityY); });
  // <!-- éé --> is 11 characters; robot and link are 2 levels: x number kMaxElementDepth - 1 is too deep
  EXPECT_EQ(e.column, 12 + 3 * (kMaxElementDepth - 2));
}

TEST(UrdfLimits, LowerAboveUpperIsRefusedAtTheLimit) {
  const std::string limit = "<limit lower=\"1\" upper=\"-1\" effort=\"1\" velocity=\"1\"/>";
  const std::string text = two_joints(limit);
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l2", kGravityY, "bad.urdf"); });
  EXPECT_EQ(e.line, line_of(text, limit));
  EXPECT_EQ(e.column, 5);
  EXPECT_NE(e.message.find("joint 'j1'"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("lower > upper"), std::string::npos) << e.message;
}

TEST(UrdfLimits, LowerEqualToUpperIsRefused) {
  for (const char* v : {"0", "0.7"}) {
    const std::string limit = std::string("<limit lower=\"") + v + "\" upper=\"" + v + "\" effort=\"1\" velocity=\"1\"/>";
    const UrdfError e = expect_error([&] { parse_urdf(two_joints(limit), "base", "l2", kGravityY); });
    EXPECT_NE(e.message.find("lower = upper"), std::string::npos) << e.message;
  }
}

TEST(UrdfLimits, OmittedBoundsAreNoLimit) {
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* limit;
    double lower, upper;
  };
  const Case cases[] = {{"<limit effort=\"1\" velocity=\"1\"/>", -inf, inf},
                        {"<limit lower=\"-0.5\" effort=\"1\" velocity=\"1\"/>", -0.5, inf},
                        {"<limit upper=\"0.5\" effort=\"1\" velocity=\"1\"/>", -inf, 0.5},
                        {"<limit lower=\"0\" effort=\"1\" velocity=\"1\"/>", 0.0, inf}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.limit);
    const Chain chain = parse_urdf(two_joints(c.limit), "base", "l2", kGravityY);
    EXPECT_EQ(chain.joints[0].lower, c.lower);
    EXPECT_EQ(chain.joints[0].upper, c.upper);
    EXPECT_EQ(chain.joints[0].velocity, 1.0);  // the rest of the <limit> still read
    EXPECT_EQ(chain.joints[1].lower, -2.0);
    EXPECT_EQ(chain.joints[1].upper, 2.0);
  }
  const Chain limited = parse_urdf(two_joints(kLimited), "base", "l2", kGravityY);
  EXPECT_EQ(limited.joints[0].lower, -1.0);
  EXPECT_EQ(limited.joints[0].upper, 1.5);
}

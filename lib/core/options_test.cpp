#include "core/options.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

namespace hairis {
namespace {

TEST(Options, ParsesItemsInOrderIgnoringSpacesAndEmptyItems) {
    Expected<OptionItems> items = parse_options(" a = 1 ;;b=x,y ; c=", "test");
    ASSERT_TRUE(items) << items.error().message;
    ASSERT_EQ(items.value().size(), 3u);
    EXPECT_EQ(items.value()[0], (std::pair<std::string, std::string>{"a", "1"}));
    EXPECT_EQ(items.value()[1], (std::pair<std::string, std::string>{"b", "x,y"}));
    EXPECT_EQ(items.value()[2], (std::pair<std::string, std::string>{"c", ""}));
    EXPECT_EQ(format_options(items.value()), "a=1;b=x,y;c=");
}

TEST(Options, RefusesMalformedItemsAndRepeatedNames) {
    EXPECT_NE(parse_options("a", "render settings").error().message.find("\"a\" is not name=value"), std::string::npos);
    EXPECT_NE(parse_options("=1", "x").error().message.find("no name"), std::string::npos);
    EXPECT_NE(parse_options("a=1;a=2", "x").error().message.find("a is given twice"), std::string::npos);
}

TEST(Options, NumbersRoundTrip) {
    for (float f : {0.1f, 1.0f / 3.0f, 1e-30f, 3.4e38f, -2.5f}) {
        const std::string text = format_number(f);
        EXPECT_EQ(std::strtof(text.c_str(), nullptr), f) << text;
    }
    for (double d : {0.1, 1.0 / 3.0, 1e-300, -7.25}) {
        const std::string text = format_number(d);
        EXPECT_EQ(std::strtod(text.c_str(), nullptr), d) << text;
    }
}

TEST(OptionReader, ReadsTypedValuesAndKeepsDefaultsForAbsentNames) {
    Expected<OptionReader> r = OptionReader::parse("n=7;x=0.25;flag=true;rgb=0.1,0.2,0.3;list=1,2,4;mode=table;seed=18446744073709551615", "t");
    ASSERT_TRUE(r);
    int n = 0, absent = 42, mode = -1;
    float x = 0;
    bool flag = false;
    Rgb rgb;
    std::vector<int> list;
    std::uint64_t seed = 0;
    EXPECT_FALSE(r.value().read("n", n, 0, 10));
    EXPECT_FALSE(r.value().read("absent", absent, 0, 100));
    EXPECT_FALSE(r.value().read("x", x, 0.0, 1.0));
    EXPECT_FALSE(r.value().read("flag", flag));
    EXPECT_FALSE(r.value().read("rgb", rgb, 0.0, 1.0));
    EXPECT_FALSE(r.value().read("list", list, 16, 1, 1024));
    EXPECT_FALSE(r.value().read_choice("mode", mode, {"uniform", "analytic", "gaussian", "table"}));
    EXPECT_FALSE(r.value().read("seed", seed));
    EXPECT_FALSE(r.value().finish());
    EXPECT_EQ(n, 7);
    EXPECT_EQ(absent, 42);
    EXPECT_EQ(x, 0.25f);
    EXPECT_TRUE(flag);
    EXPECT_EQ(rgb.g, 0.2f);
    EXPECT_EQ(list, (std::vector<int>{1, 2, 4}));
    EXPECT_EQ(mode, 3);
    EXPECT_EQ(seed, 18446744073709551615ull);
}

TEST(OptionReader, ErrorsNameTheOptionAndWhatIsAllowed) {
    auto message = [](const std::string &text, auto &&read) {
        Expected<OptionReader> r = OptionReader::parse(text, "render settings");
        Status s = read(r.value());
        return s ? s->message : std::string();
    };
    int i = 0;
    float f = 0;
    EXPECT_EQ(message("samples=0", [&](OptionReader &r) { return r.read("samples", i, 1, 100); }),
              "render settings: samples must be an integer in [1, 100] (got \"0\")");
    EXPECT_NE(message("w=nan", [&](OptionReader &r) { return r.read("w", f, 0.0, 1.0); }).find("finite number in [0, 1]"),
              std::string::npos);
    EXPECT_NE(message("w=1.5", [&](OptionReader &r) { return r.read("w", f, 0.0, 1.0); }).find("(got \"1.5\")"),
              std::string::npos);
    EXPECT_NE(message("c=1,2", [&](OptionReader &r) { Rgb c; return r.read("c", c, 0.0, 9.0); }).find("3 finite numbers"),
              std::string::npos);
    EXPECT_NE(message("m=fast", [&](OptionReader &r) { return r.read_choice("m", i, {"a", "b"}); }).find("one of a, b"),
              std::string::npos);
    EXPECT_NE(message("n=1x", [&](OptionReader &r) { return r.read("n", i, 0, 9); }).find("integer"), std::string::npos);
}

TEST(OptionReader, FinishRefusesUnknownNamesListingTheKnownOnes) {
    Expected<OptionReader> r = OptionReader::parse("samples=4;sampels=8", "render settings");
    int samples = 0, bounces = 0;
    ASSERT_FALSE(r.value().read("samples", samples, 1, 10));
    ASSERT_FALSE(r.value().read("max_bounces", bounces, 0, 10));
    const Status s = r.value().finish();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->message, "render settings: unknown option \"sampels\" (known: samples, max_bounces)");
}

}  // namespace
}  // namespace hairis

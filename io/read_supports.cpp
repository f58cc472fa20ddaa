// bbm io: the support tables of a model file — one [[table]] per registered
// support type (core/supports/registry.hpp), each read by its type's own reader
// through a TableReader (base/table_reader.hpp) over TOML: errors carry the
// file, the line and the full key. No support type is named here.
#include "core/supports/registry.hpp"
#include "io/reader.hpp"

#include <deque>
#include <memory>

namespace bbm::io::reader {

namespace {

/// One TOML table as a type's reader sees it.
class TomlTable final : public TableReader {
public:
    TomlTable(Ctx& c, const toml::table& t, Path p, Names* names, const ModelScale& scale)
        : c_(c), t_(t), p_(std::move(p)), names_(names), scale_(scale) {}

    void check_keys(std::span<const std::string_view> allowed, std::string_view what,
                    std::span<const std::string_view> elsewhere) override {
        reader::check_keys(c_, t_, p_, allowed, elsewhere, what);
    }
    bool has(std::string_view key) const override { return t_.contains(key); }
    std::string name() override { return read_name(c_, t_, p_, *names_); }
    std::optional<double> number(std::string_view key, const Bounds& b) override {
        return reader::number(c_, t_, p_, key, b);
    }
    double required_number(std::string_view key, const Bounds& b) override {
        return reader::required_number(c_, t_, p_, key, b);
    }
    std::optional<std::int64_t> integer(std::string_view key, const Bounds& b) override {
        return whole_number(c_, t_, p_, key, b);
    }
    std::optional<bool> boolean(std::string_view key) override { return reader::boolean(c_, t_, p_, key); }
    // Near the model: reader::to_position checks every point against Ctx::scale.
    std::optional<Vec2> point(std::string_view key) override { return reader::point(c_, t_, p_, key); }
    Vec2 required_point(std::string_view key) override { return reader::required_point(c_, t_, p_, key); }
    std::optional<std::vector<std::array<Vec2, 2>>> segments(std::string_view key, std::string_view what,
                                                             std::string_view ends) override {
        const toml::node* n = find(c_, t_, p_, key);
        if (!n) return std::nullopt;
        const Path kp = p_.key(key);
        const toml::array& a = to_array(c_, *n, kp, "an array of " + std::string(what));
        std::vector<std::array<Vec2, 2>> out;
        for_each_element(c_, a, kp, [&](const toml::node& e, const Path& ep) {
            const toml::array& pair = to_array(c_, e, ep, "a segment [[x1, y1], [x2, y2]]");
            if (pair.size() != 2) c_.fail(e, ep, "a segment is 2 points [from, to], got " + std::to_string(pair.size()));
            const Vec2 from = to_position(c_, pair[0], ep.at(0)), to = to_position(c_, pair[1], ep.at(1));
            if (!(norm(to - from) > 0)) c_.fail(e, ep, std::string(ends) + " are the same point " + fmt(from));
            out.push_back({from, to});
        });
        return out;
    }
    std::unique_ptr<TableReader> table(std::string_view key, std::string_view what) override {
        const toml::node* n = find(c_, t_, p_, key);
        if (!n) return nullptr;
        const Path kp = p_.key(key);
        return std::make_unique<TomlTable>(c_, to_table(c_, *n, kp, std::string(what)), kp, names_, scale_);
    }
    [[noreturn]] void fail(std::string_view key, const std::string& message) override {
        if (key.empty()) c_.fail(t_, p_, message);
        const toml::node* n = t_.get(key);
        c_.fail(n ? line(*n) : line(t_), p_.key(key), message);
    }
    std::string owner() const override { return c_.in_owner(); }
    const ModelScale& scale() const override { return scale_; }

private:
    Ctx& c_;
    const toml::table& t_;
    Path p_;
    Names* names_;
    const ModelScale& scale_;
};

} // namespace

void read_supports(Ctx& c, const toml::table& doc, SupportSpecs& specs, Names& supports, const ModelScale& scale) {
    // Each type's tables, named apart from every other type's: install stages name any.
    std::deque<std::string> words; // the Names' text, alive while they are
    std::vector<Names> kinds;
    for_each_support_type([&](auto type) {
        using T = typename decltype(type)::type;
        const std::string& table = words.emplace_back(T::table);
        const std::string& what = words.emplace_back(std::string(T::table) + " set");
        const std::string& plural = words.emplace_back(std::string(T::table) + " sets");
        Names& names = kinds.emplace_back(Names{what, plural, table, {}, {}});
        read_tables(c, doc, T::table, [&](const toml::table& t, const Path& p, std::size_t) {
            TomlTable reader(c, t, p, &names, scale);
            support_state<T>(specs).push_back(T::read(reader));
        });
    });
    for (std::size_t later = 1; later < kinds.size(); ++later)
        for (std::size_t i = 0; i < kinds[later].names.size(); ++i)
            for (std::size_t earlier = 0; earlier < later; ++earlier) {
                const Names& mine = kinds[later];
                const Names& theirs = kinds[earlier];
                const auto other = std::ranges::find(theirs.names, mine.names[i]);
                if (other == theirs.names.end()) continue;
                const Path np = Path{}.key(std::string(mine.table)).at(i).key("name");
                const auto j = std::size_t(other - theirs.names.begin());
                c.fail(c.source->line_of(np.full), np,
                       "name " + quoted(mine.names[i]) + " is already used by " + std::string(theirs.table) + "[" +
                           std::to_string(j) + "] (line " + std::to_string(theirs.lines[j]) +
                           "): the support sets of every type share their names (install stages name any)");
            }
    for (const Names& kind : kinds) supports.names.insert(supports.names.end(), kind.names.begin(), kind.names.end());
}

} // namespace bbm::io::reader

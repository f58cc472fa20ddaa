// bbm base: one table of a model file as a type that reads itself sees it.
//
// A support type (core/supports/) or another self-declaring section reads its
// table through this interface, which names no file format: the model-file
// reader (io/) implements it over a TOML table, with every error carrying the
// file, the line and the full key. So a type's reading — its keys, their bounds,
// the rules between them — lives in the type's own file, below the layer that
// parses files, and a new type needs no line in the reader.
//
// Every read checks the value against the bounds given (or the model's scale:
// lengths and positions against the model's extent, ModelScale); every failure
// throws InputError naming the key (an empty key: the table itself).
#pragma once

#include "base/bounds.hpp"
#include "base/keys.hpp"
#include "base/vec2.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bbm {

/// How large the model is, for the checks of lengths and positions a table gives
/// (a key in the wrong unit is refused, not silently snapped to the nearest
/// block): the extent of its regions and the size of its smallest blocks.
struct ModelScale {
    Box2 extent;              ///< of every region's outline
    double block_size = 0.0;  ///< the smallest pattern size of a region with blocks (0: none)
    double size() const { return extent.empty() ? 0.0 : std::max(extent.width(), extent.height()); }
    /// Within the extent grown by its own size on every side.
    bool near(Vec2 p) const {
        const double s = size();
        return !extent.empty() && p.x >= extent.lo.x - s && p.x <= extent.hi.x + s && p.y >= extent.lo.y - s &&
               p.y <= extent.hi.y + s;
    }
    /// Overlapping that neighbourhood (a box may reach far beyond the model to
    /// take all of one side; one wholly beside it selects nothing it means).
    bool near(const Box2& b) const {
        const double s = size();
        return !extent.empty() && b.hi.x >= extent.lo.x - s && b.lo.x <= extent.hi.x + s &&
               b.hi.y >= extent.lo.y - s && b.lo.y <= extent.hi.y + s;
    }
};

class TableReader {
public:
    virtual ~TableReader() = default;
    /// Refuses a key outside `allowed` (with "did you mean"); `what` names the table; one in `elsewhere` (another table's of the
    /// same keys: a bolt's in a dowel) as not applying to `what` ("a dowel set").
    virtual void check_keys(std::span<const std::string_view> allowed, std::string_view what,
                            std::span<const std::string_view> elsewhere = {}) = 0;
    virtual bool has(std::string_view key) const = 0;
    /// The required, non-empty `name`, unique among the named tables of its kind.
    virtual std::string name() = 0;
    virtual std::optional<double> number(std::string_view key, const Bounds& bounds) = 0;
    virtual std::optional<std::int64_t> integer(std::string_view key, const Bounds& bounds) = 0;
    virtual std::optional<bool> boolean(std::string_view key) = 0;
    /// [x, y], within the model's neighbourhood (ModelScale::near).
    virtual std::optional<Vec2> point(std::string_view key) = 0;
    /// [[[x1, y1], [x2, y2]], ...]: segments of non-zero length near the model;
    /// `what` names them in messages ("bars [[x1, y1], [x2, y2]] (head, toe)"),
    /// `ends` their two ends ("head and toe").
    virtual std::optional<std::vector<std::array<Vec2, 2>>> segments(std::string_view key, std::string_view what,
                                                                     std::string_view ends) = 0;
    /// The inline table `key`, read by its own reader; null when absent.
    virtual std::unique_ptr<TableReader> table(std::string_view key, std::string_view what) = 0;
    [[noreturn]] virtual void fail(std::string_view key, const std::string& message) = 0;
    /// "<table> set 'roof': ", for messages that would otherwise make the user count tables.
    virtual std::string owner() const = 0;
    virtual const ModelScale& scale() const = 0;

    /// As number() and point(), but a missing key is an error ("missing required key").
    virtual double required_number(std::string_view key, const Bounds& bounds) = 0;
    virtual Vec2 required_point(std::string_view key) = 0;
    /// Every number, integer and boolean key of `keys` that fills a field (its
    /// `set`) and belongs to tables of type `type` (its `only`; empty: all).
    template <class Spec, std::size_t N>
    void declared(const Key<Spec> (&keys)[N], Spec& spec, std::string_view type = "") {
        for (const Key<Spec>& k : keys) {
            if (!k.set || (!type.empty() && !key_applies(k, type))) continue;
            std::optional<double> v;
            if (k.kind == KeyKind::number) v = k.required ? required_number(k.key, k.bounds) : number(k.key, k.bounds);
            else if (k.kind == KeyKind::integer) {
                if (auto i = integer(k.key, k.bounds)) v = double(*i);
            } else if (k.kind == KeyKind::boolean) {
                if (auto b = boolean(k.key)) v = *b ? 1.0 : 0.0;
            }
            if (v) k.set(spec, *v);
            else if (k.required) fail(k.key, "is required");
        }
    }
    /// A length (m) that must resolve the model: above `floor` of its smallest
    /// blocks' size, so that a value in the wrong unit is refused.
    void check_length_resolves(std::string_view key, double length, double floor = 1e-3) {
        const double d = scale().block_size;
        if (d > 0.0 && !(length >= floor * d))
            fail(key, shortest_text(length) + " m is below " + shortest_text(floor) +
                          " of the model's smallest block size (" + shortest_text(d) +
                          " m): a length in another unit? Give it in metres");
    }
};

} // namespace bbm

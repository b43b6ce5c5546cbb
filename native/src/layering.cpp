#include "wiresculpt/layering.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "wiresculpt/contact.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/in_plane.hpp"
#include "wiresculpt/mechanism.hpp"
#include "wiresculpt/stability.hpp"
#include "wire_names.hpp"

namespace wiresculpt {
namespace {

constexpr double kEps = 1e-9;

// The objective of layering.hpp, lexicographic.
struct Key {
  double max = 0.0;
  int nulls = 0;
  double sum = 0.0;
  int two = 0;
  int unbal = 0;  // key 5: wires whose crossings are all decided and that do not balance in plane
};

bool less(const Key& a, const Key& b) {
  if (a.max < b.max - kEps) return true;
  if (a.max > b.max + kEps) return false;
  if (a.nulls != b.nulls) return a.nulls < b.nulls;
  if (a.sum < b.sum - kEps) return true;
  if (a.sum > b.sum + kEps) return false;
  if (a.two != b.two) return a.two < b.two;
  return a.unbal < b.unbal;
}

bool allowed(const LayeringOptions& options, int c, int side) {
  return options.allowed_hooks.empty() || options.allowed_hooks[c][side];
}

using detail::crossing_list;
using detail::join;
using detail::quoted;
using detail::wire_list;

class Search {
 public:
  Search(const Network& net, const LayeringOptions& options, const ProgressFn& progress)
      : net_(net), opt_(options), progress_(progress), checker_(net, options.contact) {
    P_ = static_cast<int>(net.wires.size());
    C_ = static_cast<int>(net.crossings.size());
    full_ = P_ == 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << P_) - 1);
    cost_.resize(C_);
    minhook_.resize(C_);
    relaxed_.resize(C_);
    constexpr double forbidden = std::numeric_limits<double>::infinity();
    for (int c = 0; c < C_; ++c) {
      // A forbidden hook (LayeringOptions::allowed_hooks) costs +inf: never enumerated, and the
      // prunings compare with the cheaper allowed hook.
      const bool minus = allowed(options, c, 0), plus = allowed(options, c, 1);
      cost_[c] = {minus ? hook_metric(net, c, -1, options.contact) : forbidden,
                  plus ? hook_metric(net, c, 1, options.contact) : forbidden};
      minhook_[c] = std::min(cost_[c][0], cost_[c][1]);
      relaxed_[c] = minus && plus ? 2 : (plus ? 1 : (minus ? -1 : 0));
    }
    hooks_.assign(C_, 0);
    neighbours_.assign(P_, 0);
    for (int w = 0; w < P_; ++w) crossing_lists_.push_back(net.crossings_of(w));
    for (const auto& x : net.crossings) {
      neighbours_[x.wires[0]] |= std::uint64_t{1} << x.wires[1];
      neighbours_[x.wires[1]] |= std::uint64_t{1} << x.wires[0];
    }
  }

  // One full search; `pairs` allows two-wire steps after the first pair.
  void run(bool pairs) {
    pairs_ = pairs;
    stopped_ = false;
    base_ = reported_;
    root_fraction_ = 0.0;
    visited_.clear();
    mask_ = 0;
    order_.clear();
    steps_.clear();
    std::fill(hooks_.begin(), hooks_.end(), 0);
    cur_ = Key{};
    min_null_ = 1e300;
    dfs(0);
  }

  bool found() const { return have_best_; }
  bool stopped() const { return stopped_; }

  const Network& net_;
  const LayeringOptions& opt_;
  const ProgressFn& progress_;
  StabilityChecker checker_;
  int P_ = 0, C_ = 0;
  std::uint64_t full_ = 0;
  std::vector<std::array<double, 2>> cost_;  // [c][0]: hook -1, [c][1]: hook +1
  std::vector<double> minhook_;
  // Per crossing: the pyramids of every allowed hook at once (2: both, +-1: the one allowed, 0:
  // none), for prunings (d) and (e).
  std::vector<int> relaxed_;
  std::vector<std::uint64_t> neighbours_;  // per wire: the wires it crosses
  // balances_in_plane per wire and hooks of its crossings (key: wire id, then hooks).
  mutable std::unordered_map<std::string, bool> balance_memo_;
  std::vector<std::vector<int>> crossing_lists_;  // per wire: Network::crossings_of
  mutable std::vector<int> scratch_;              // hooks_ with a child's choice applied

  // Current path.
  bool pairs_ = false;
  std::uint64_t mask_ = 0;
  std::vector<int> order_;
  std::vector<std::vector<int>> steps_;
  std::vector<int> hooks_;
  Key cur_;
  double min_null_ = 1e300;  // smallest cheaper-hook cost among decided null crossings

  // Best complete structure and the largest stable partial assembly.
  bool have_best_ = false;
  Key best_;
  std::vector<int> best_hooks_, best_order_;
  std::vector<std::vector<int>> best_steps_;
  int deepest_ = 0;
  std::vector<int> deep_hooks_, deep_order_;
  std::vector<std::vector<int>> deep_steps_;

  std::unordered_set<std::string> visited_;
  long nodes_ = 0;
  bool stopped_ = false;
  long node_limit_ = 0;    // stop when nodes_ reaches it; 0 = no limit
  bool in_plane_ = false;  // count key 5 (the second pass, layering())
  std::vector<std::string> warnings_;
  std::vector<int> oversized_warned_;
  double root_fraction_ = 0.0;
  double base_ = 0.0, reported_ = 0.0;  // progress: start of this search, last reported

 private:
  bool in(int w, std::uint64_t m) const { return (m >> w) & 1u; }

  struct Child {
    Key lb, key;
    int group = 0;
    std::vector<signed char> choice;  // per new crossing of the group
    double min_null = 1e300;
  };

  struct Group {
    std::vector<int> wires;
    std::vector<int> fresh;        // crossings decided by this step, sorted by minhook descending
    std::vector<double> open_min;  // minhook of crossings still undecided after it, ascending
    std::vector<double> open_prefix;
    std::vector<int> completes;    // wires whose crossings are all decided by this step
  };

  bool complete(int w, std::uint64_t m) const { return in(w, m) && (neighbours_[w] & ~m) == 0; }

  // Key 5 (layering.hpp): does wire w balance in plane under `hooks`? Memoised.
  bool balanced(int w, const std::vector<int>& hooks) const {
    std::string key(1, static_cast<char>(w));
    for (int c : crossing_lists_[w]) key.push_back(static_cast<char>(hooks[c] + 1));
    const auto it = balance_memo_.find(key);
    if (it != balance_memo_.end()) return it->second;
    const bool ok = balances_in_plane(net_, w, hooks);
    balance_memo_.emplace(std::move(key), ok);
    return ok;
  }

  Key lower_bound(const Key& k, const Group& g) const {
    // Undecided crossings whose cheaper hook exceeds the maximum must be null if the maximum is
    // to stay; the others add at least their cheaper hook.
    Key lb = k;
    const auto split = std::upper_bound(g.open_min.begin(), g.open_min.end(), k.max + kEps);
    const auto n_cheap = static_cast<std::size_t>(split - g.open_min.begin());
    lb.nulls += static_cast<int>(g.open_min.size() - n_cheap);
    lb.sum += g.open_prefix[n_cheap];
    return lb;
  }

  bool make_group(std::vector<int> wires, Group& g) {
    std::uint64_t after = mask_;
    for (int w : wires) after |= std::uint64_t{1} << w;
    std::vector<int> touched(wires.size(), 0);
    for (int c = 0; c < C_; ++c) {
      const int a = net_.crossings[c].wires[0], b = net_.crossings[c].wires[1];
      const bool decided_before = in(a, mask_) && in(b, mask_);
      const bool decided_after = in(a, after) && in(b, after);
      if (decided_after && !decided_before) {
        g.fresh.push_back(c);
        for (std::size_t k = 0; k < wires.size(); ++k)
          if (a == wires[k] || b == wires[k]) touched[k] = 1;
      } else if (!decided_after) {
        g.open_min.push_back(minhook_[c]);
      }
    }
    for (int t : touched)
      if (!t) return false;  // a wire of this step would touch nothing
    if (static_cast<int>(g.fresh.size()) > opt_.max_step_crossings) {
      for (int w : wires)
        if (std::find(oversized_warned_.begin(), oversized_warned_.end(), w) == oversized_warned_.end()) {
          oversized_warned_.push_back(w);
          warnings_.push_back("wire " + quoted(net_, w) + " was not tried in a step with " +
                              std::to_string(g.fresh.size()) + " new crossings (more than max_step_crossings = " +
                              std::to_string(opt_.max_step_crossings) + "); the search may have missed orders");
        }
      return false;
    }
    std::stable_sort(g.fresh.begin(), g.fresh.end(), [&](int x, int y) { return minhook_[x] > minhook_[y]; });
    std::sort(g.open_min.begin(), g.open_min.end());
    g.open_prefix.assign(g.open_min.size() + 1, 0.0);
    for (std::size_t k = 0; k < g.open_min.size(); ++k) g.open_prefix[k + 1] = g.open_prefix[k] + g.open_min[k];
    if (in_plane_)
      for (int w = 0; w < P_; ++w)
        if (complete(w, after) && !complete(w, mask_)) g.completes.push_back(w);
    g.wires = std::move(wires);
    return true;
  }

  // Every non-dominated hook choice of the group's new crossings (layering.hpp, pruning b) that
  // can still beat the best complete structure. `greedy`: only the cheaper hook of each crossing
  // (one child per number of nulls), to reach a first complete structure quickly.
  void enumerate(const Group& g, int gi, std::vector<Child>& out, bool greedy) const {
    const auto& N = g.fresh;
    const int m = static_cast<int>(N.size());
    const int two = cur_.two + (g.wires.size() > (order_.empty() ? 2u : 1u) ? 1 : 0);
    // A hook dearer than the best maximum can only make a worse structure.
    const double cap = have_best_ ? best_.max + kEps : 1e300;
    std::vector<std::array<signed char, 2>> options(m);
    std::vector<int> n_options(m), digit(m);
    if (!g.completes.empty()) scratch_ = hooks_;
    for (int z = 0; z <= m; ++z) {
      if (z > 0) {
        const double lowest = minhook_[N[z - 1]];
        if (!(lowest > cur_.max + kEps)) break;                     // a null here is never optimal
        if (z < m && !(lowest > minhook_[N[z]] + kEps)) continue;  // would split a tie
      }
      const int free = m - z;
      // The cheapest choice of this z, a lower bound for all of them.
      Key base = cur_;
      base.two = two;
      base.nulls += z;
      bool possible = true;
      for (int q = 0; q < free; ++q) {
        const int c = N[z + q];
        const signed char cheap = cost_[c][1] <= cost_[c][0] ? 1 : -1;
        const signed char dear = static_cast<signed char>(-cheap);
        n_options[q] = 0;
        if (minhook_[c] <= cap) options[q][n_options[q]++] = cheap;
        if (!greedy && cost_[c][dear > 0 ? 1 : 0] <= cap) options[q][n_options[q]++] = dear;
        if (n_options[q] == 0) possible = false;
        base.max = std::max(base.max, minhook_[c]);
        base.sum += minhook_[c];
      }
      if (!possible) continue;
      double min_null = min_null_;
      if (z > 0) min_null = std::min(min_null, minhook_[N[z - 1]]);
      if (min_null <= base.max + kEps) continue;  // some null crossing could be hooked for free
      if (have_best_ && !less(lower_bound(base, g), best_)) continue;
      std::fill(digit.begin(), digit.end(), 0);
      while (true) {
        Key k = cur_;
        k.two = two;
        k.nulls += z;
        for (int q = 0; q < free; ++q) {
          const double e = cost_[N[z + q]][options[q][digit[q]] > 0 ? 1 : 0];
          k.max = std::max(k.max, e);
          k.sum += e;
        }
        if (min_null > k.max + kEps && !g.completes.empty()) {
          for (int q = 0; q < free; ++q) scratch_[N[z + q]] = options[q][digit[q]];
          for (int q = 0; q < z; ++q) scratch_[N[q]] = 0;
          for (int w : g.completes) k.unbal += balanced(w, scratch_) ? 0 : 1;
        }
        if (min_null > k.max + kEps) {
          const Key lb = lower_bound(k, g);
          if (!have_best_ || less(lb, best_)) {
            Child ch;
            ch.group = gi;
            ch.key = k;
            ch.lb = lb;
            ch.min_null = min_null;
            ch.choice.assign(m, 0);
            for (int q = 0; q < free; ++q) ch.choice[z + q] = options[q][digit[q]];
            out.push_back(std::move(ch));
          }
        }
        int q = 0;
        while (q < free && ++digit[q] == n_options[q]) digit[q++] = 0;
        if (q == free) break;
      }
    }
  }

  void tick() {
    ++nodes_;
    if ((nodes_ & 127) == 0) {
      // Monotone: the second (two-hand) search continues from where the first left off.
      reported_ = std::max(reported_, base_ + (1.0 - base_) * root_fraction_);
      report_progress(progress_, "layering", std::min(reported_, 0.99));
    }
    if (node_limit_ > 0 && nodes_ >= node_limit_) stopped_ = true;
  }

  std::string state_key() const {
    // The two-hand count is part of the state: it is part of the objective (key 4).
    std::string key(sizeof mask_ + hooks_.size() + 1, '\0');
    key.back() = static_cast<char>(std::min(cur_.two, 127));
    for (std::size_t b = 0; b < sizeof mask_; ++b) key[b] = static_cast<char>((mask_ >> (8 * b)) & 0xffu);
    for (std::size_t c = 0; c < hooks_.size(); ++c) key[sizeof mask_ + c] = static_cast<char>(hooks_[c] + 1);
    return key;
  }

  void dfs(int depth) {
    if (stopped_) return;
    if (mask_ == full_) {
      if (!have_best_ || less(cur_, best_)) {
        have_best_ = true;
        best_ = cur_;
        best_hooks_ = hooks_;
        best_order_ = order_;
        best_steps_ = steps_;
      }
      return;
    }
    // The groups a step may add.
    std::vector<Group> groups;
    if (mask_ == 0) {
      for (int a = 0; a < P_; ++a)
        for (int b = a + 1; b < P_; ++b) {
          Group g;
          if (make_group({a, b}, g)) groups.push_back(std::move(g));
        }
    } else {
      for (int a = 0; a < P_; ++a) {
        if (in(a, mask_)) continue;
        Group g;
        if (make_group({a}, g)) groups.push_back(std::move(g));
      }
      if (pairs_)
        for (int a = 0; a < P_; ++a)
          for (int b = a + 1; b < P_; ++b) {
            if (in(a, mask_) || in(b, mask_)) continue;
            Group g;
            if (make_group({a, b}, g)) groups.push_back(std::move(g));
          }
    }
    // First the cheapest child of every step, to reach a complete structure (and a bound) fast;
    // then every child that can still improve on the best (those already entered are skipped).
    for (int round = have_best_ ? 1 : 0; round < 2; ++round) {
      std::vector<Child> children;
      for (int gi = 0; gi < static_cast<int>(groups.size()); ++gi) {
        const std::size_t before = children.size();
        enumerate(groups[gi], gi, children, round == 0);
        if (round == 0 || children.size() - before < 16) continue;  // cheaper to try a few one by one
        // Pruning (d): every allowed hook's pyramid at every new crossing; if that fails, every
        // choice fails.
        std::vector<int> wires = order_;
        for (int w : groups[gi].wires) wires.push_back(w);
        for (int c : groups[gi].fresh) hooks_[c] = relaxed_[c];
        const bool ok = checker_.check(wires, hooks_, wires.size() == 2).stable;
        for (int c : groups[gi].fresh) hooks_[c] = 0;
        if (!ok) children.resize(before);
      }
      explore(children, groups, depth);
      if (stopped_) return;
    }
  }

  void explore(std::vector<Child>& children, const std::vector<Group>& groups, int depth) {
    std::stable_sort(children.begin(), children.end(), [](const Child& x, const Child& y) {
      if (less(x.lb, y.lb)) return true;
      if (less(y.lb, x.lb)) return false;
      return less(x.key, y.key);
    });
    for (std::size_t i = 0; i < children.size(); ++i) {
      if (stopped_) return;
      if (depth == 0) root_fraction_ = static_cast<double>(i) / static_cast<double>(children.size());
      const Child& ch = children[i];
      if (have_best_ && !less(ch.lb, best_)) continue;
      const Group& g = groups[ch.group];
      // Apply.
      const Key saved_key = cur_;
      const double saved_null = min_null_;
      for (std::size_t q = 0; q < g.fresh.size(); ++q) hooks_[g.fresh[q]] = ch.choice[q];
      for (int w : g.wires) {
        mask_ |= std::uint64_t{1} << w;
        order_.push_back(w);
      }
      steps_.push_back(g.wires);
      cur_ = ch.key;
      min_null_ = ch.min_null;
      if (visited_.insert(state_key()).second) {
        tick();
        if (checker_.check(order_, hooks_, order_.size() == 2).stable) {
          if (static_cast<int>(order_.size()) > deepest_) {
            deepest_ = static_cast<int>(order_.size());
            deep_hooks_ = hooks_;
            deep_order_ = order_;
            deep_steps_ = steps_;
          }
          dfs(depth + 1);
        }
      }
      // Undo.
      for (int c : g.fresh) hooks_[c] = 0;
      for (std::size_t k = 0; k < g.wires.size(); ++k) {
        mask_ &= ~(std::uint64_t{1} << order_.back());
        order_.pop_back();
      }
      steps_.pop_back();
      cur_ = saved_key;
      min_null_ = saved_null;
    }
  }
};

// Why no stable assembly exists, naming a wire and its crossings; its cause into `cause`.
std::string explain(const Network& net, const Search& s, bool tried_pairs, LayeringCause& cause) {
  const int P = static_cast<int>(net.wires.size());
  std::vector<char> in(P, 0);
  for (int w : s.deep_order_) in[w] = 1;
  auto crossings_with_set = [&](int w) {
    std::vector<int> out;
    for (int c = 0; c < static_cast<int>(net.crossings.size()); ++c) {
      const auto& x = net.crossings[c];
      if ((x.wires[0] == w && in[x.wires[1]]) || (x.wires[1] == w && in[x.wires[0]])) out.push_back(c);
    }
    return out;
  };
  const std::string also = tried_pairs ? " (steps adding two wires at once were also tried)" : "";
  if (s.deep_order_.empty()) {
    // No stable pair: name the pair with the most crossings.
    int ba = -1, bb = -1;
    std::vector<int> bc;
    for (int a = 0; a < P; ++a)
      for (int b = a + 1; b < P; ++b) {
        std::vector<int> cs;
        for (int c = 0; c < static_cast<int>(net.crossings.size()); ++c)
          if (net.crossings[c].wires[0] == a && net.crossings[c].wires[1] == b) cs.push_back(c);
        if (cs.size() > bc.size()) {
          ba = a;
          bb = b;
          bc = cs;
        }
      }
    if (ba < 0) {
      cause = LayeringCause::no_crossings;
      return "no two wires cross, so no wire can hold another";
    }
    cause = LayeringCause::no_stable_pair;
    return "no pair of wires is stable even under forces only (Sec. 4.2), so no assembly can start: wire " +
           quoted(net, bb) + " cannot be held stably by wire " + quoted(net, ba) + " at crossing" +
           (bc.size() > 1 ? "s " : " ") + crossing_list(bc) + " in any hook configuration";
  }
  int worst = -1;
  std::vector<int> worst_c;
  for (int w = 0; w < P; ++w) {
    if (in[w]) continue;
    auto cs = crossings_with_set(w);
    if (worst < 0 || cs.size() > worst_c.size()) {
      worst = w;
      worst_c = cs;
    }
  }
  cause = LayeringCause::no_assembly_order;
  const std::string base = "no stable assembly order exists under the paper's model (Sec. 4.1-4.2): after the "
                           "largest stable partial assembly (wires " + wire_list(net, s.deep_order_) + "), ";
  if (worst_c.empty())
    return base + "wire " + quoted(net, worst) + " crosses none of them" + also;
  return base + "wire " + quoted(net, worst) + " cannot be added stably in any hook configuration of its crossing" +
         (worst_c.size() > 1 ? "s " : " ") + crossing_list(worst_c) + " with them" + also;
}

// The hooks allowed_hooks forbids (LayeringResult::forbidden_hooks).
int forbidden_count(const LayeringOptions& options) {
  int count = 0;
  for (const auto& a : options.allowed_hooks) count += !a[0] + !a[1];
  return count;
}

// Appended to a reason when hooks were forbidden: the verdict is over the allowed ones only.
std::string forbidden_note(const LayeringOptions& options) {
  const int count = forbidden_count(options);
  std::vector<int> at;
  for (std::size_t c = 0; c < options.allowed_hooks.size(); ++c) {
    const auto& a = options.allowed_hooks[c];
    if (!a[0] || !a[1]) at.push_back(static_cast<int>(c));
  }
  if (count == 0) return "";
  return " (with " + std::to_string(count) + " hook" + (count == 1 ? "" : "s") +
         " forbidden because the target shape cannot realise them, at crossing" + (at.size() == 1 ? " " : "s ") +
         crossing_list(at) + ")";
}

}  // namespace

const char* cause_name(LayeringCause cause) {
  switch (cause) {
    case LayeringCause::none: return "none";
    case LayeringCause::alone: return "alone";
    case LayeringCause::disconnected: return "disconnected";
    case LayeringCause::no_crossings: return "no_crossings";
    case LayeringCause::no_stable_pair: return "no_stable_pair";
    case LayeringCause::no_assembly_order: return "no_assembly_order";
    case LayeringCause::mechanism: return "mechanism";
    case LayeringCause::search_incomplete: return "search_incomplete";
  }
  return "none";
}

std::vector<std::array<bool, 2>> too_close_hooks(const Network& net, double contact_angle, double angle_tolerance) {
  const int C = static_cast<int>(net.crossings.size());
  std::vector<std::array<bool, 2>> ok(C, {true, true});
  const double lmin = net.min_segment, margin = 1e-9;
  if (!(lmin > 0.0)) return ok;
  const double widest = contact_angle / 2.0 + angle_tolerance;
  for (int w = 0; w < static_cast<int>(net.wires.size()); ++w) {
    const WireSpec& wire = net.wires[w];
    for (const Network::Gap& gap : net.gaps_of(w)) {
      if (gap.arc >= 2.0 * lmin * (1.0 - margin)) continue;  // a free bending point between them
      const int ca = gap.a, cb = gap.b;
      const Vec3 piece = wire.points[gap.vb] - wire.points[gap.va];
      if (piece.norm() < lmin * (1.0 - margin)) {
        ok[ca] = ok[cb] = {false, false};
        continue;
      }
      for (const auto& [c, edge] : {std::pair{ca, Vec3(piece)}, std::pair{cb, Vec3(-piece)}}) {
        const Vec3 d = crossing_direction(net, c);
        const double sign = net.crossings[c].wires[0] == w ? 1.0 : -1.0;  // hook +1: h = +d on wires[0], -d on wires[1]
        for (int k = 0; k < 2; ++k) {
          const Vec3 h = (k == 1 ? sign : -sign) * d;
          const double angle = std::atan2(edge.cross(h).norm(), edge.dot(h));
          if (angle > widest * (1.0 + margin)) ok[c][k] = false;
        }
      }
    }
  }
  return ok;
}

namespace {

void check_input(const Network& net, const LayeringOptions& options) {
  const int P = static_cast<int>(net.wires.size());
  const int C = static_cast<int>(net.crossings.size());
  if (P == 0) throw InputError("layering needs at least one wire");
  if (P > 64) throw InputError("layering handles at most 64 wires, got " + std::to_string(P));
  if (options.max_nodes < 0) throw InputError("max_nodes must be >= 0 (0 means no limit)");
  if (options.in_plane_nodes < 0) throw InputError("in_plane_nodes must be >= 0 (0 means no limit)");
  if (options.max_step_crossings < 1 || options.max_step_crossings > 30)
    throw InputError("max_step_crossings must be between 1 and 30");
  if (!options.allowed_hooks.empty() && static_cast<int>(options.allowed_hooks.size()) != C)
    throw InputError("allowed_hooks has " + std::to_string(options.allowed_hooks.size()) + " entries for " +
                     std::to_string(C) + " crossings (one per crossing, or none)");
  for (const auto& x : net.crossings)
    if (x.wires[0] < 0 || x.wires[0] >= P || x.wires[1] < 0 || x.wires[1] >= P || x.wires[0] == x.wires[1])
      throw InputError("the network has a crossing with invalid wire ids; build it with build_network");
}

// The layering with the hooks the target shape cannot realise (too_close_hooks) forbidden, and
// the hooks so forbidden named in the result.
LayeringResult with_too_close_forbidden(const Network& net, const LayeringOptions& options,
                                        const ProgressFn& progress) {
  const int C = static_cast<int>(net.crossings.size());
  if (!std::isfinite(options.too_close_angle_tolerance) || options.too_close_angle_tolerance < 0.0)
    throw InputError("too_close_angle_tolerance must be a finite angle >= 0 (radians), got " +
                     std::to_string(options.too_close_angle_tolerance));
  LayeringOptions limited = options;
  limited.forbid_too_close = false;
  const auto realisable = too_close_hooks(net, options.contact.contact_angle, options.too_close_angle_tolerance);
  if (limited.allowed_hooks.empty()) limited.allowed_hooks.assign(C, {true, true});
  std::vector<std::array<int, 2>> forbidden;
  for (int c = 0; c < C; ++c)
    for (int k = 0; k < 2; ++k)
      if (limited.allowed_hooks[c][k] && !realisable[c][k]) {
        limited.allowed_hooks[c][k] = false;
        forbidden.push_back({c, k == 1 ? 1 : -1});
      }
  LayeringResult r = layering(net, limited, progress);
  r.too_close_forbidden = forbidden;
  return r;
}

// Why the wires do not hang together through their crossings, or "" when they do; its cause
// (alone or disconnected) into `cause`.
std::string disconnected(const Network& net, LayeringCause& cause) {
  const int P = static_cast<int>(net.wires.size());
  std::vector<int> comp(P, -1);
  std::vector<int> stack{0};
  comp[0] = 0;
  while (!stack.empty()) {
    const int w = stack.back();
    stack.pop_back();
    for (const auto& x : net.crossings)
      for (int k = 0; k < 2; ++k)
        if (x.wires[k] == w && comp[x.wires[1 - k]] < 0) {
          comp[x.wires[1 - k]] = 0;
          stack.push_back(x.wires[1 - k]);
        }
  }
  for (int w = 0; w < P; ++w) {
    if (comp[w] >= 0) continue;
    bool any = false;
    for (const auto& x : net.crossings) any = any || x.wires[0] == w || x.wires[1] == w;
    cause = any ? LayeringCause::disconnected : LayeringCause::alone;
    return any ? "wire " + quoted(net, w) + " and the wires it crosses are not connected to wire " +
                     quoted(net, 0) + " through any crossing; a sculpture must hang together"
               : "wire " + quoted(net, w) + " crosses no other wire, so nothing can hold it";
  }
  return "";
}

// Why no hook configuration can make the finished sculpture stable, `relaxed` being the check
// with both hooks' pyramids at every crossing.
// What moves when even both hooks at every crossing do not hold, or what cannot be balanced, with
// its advice: named from the null space of the crossings as ball joints (mechanism.hpp), rather
// than the LP's failing load, whose wire need not be the one that moves.
std::string what_moves(const Network& net, const StabilityResult& relaxed) {
  const int P = static_cast<int>(net.wires.size());
  const int C = static_cast<int>(net.crossings.size());
  std::string reason;
  const Mechanism mechanism = find_mechanism(net);
  if (!mechanism.moving.empty()) {
    reason += mechanism_message(net, mechanism);
  } else {  // rigid as ball joints, yet the allowed pyramids do not span (forbidden hooks, degenerate contact angle)
    int w = relaxed.failed_wire;
    if (w < 0) {  // the combined load failed: name the wire with the fewest crossings
      std::vector<int> count(P, 0);
      for (const auto& x : net.crossings) ++count[x.wires[0]], ++count[x.wires[1]];
      w = static_cast<int>(std::min_element(count.begin(), count.end()) - count.begin());
    }
    std::vector<int> cs;
    for (int c = 0; c < C; ++c)
      if (net.crossings[c].wires[0] == w || net.crossings[c].wires[1] == w) cs.push_back(c);
    static const char* what[6] = {"a force along x", "a force along y", "a force along z",
                                  "a torque about x", "a torque about y", "a torque about z"};
    reason += "the wires cannot balance " +
              (relaxed.failed_component >= 0 ? std::string(what[relaxed.failed_component])
                                             : std::string("every load")) +
              " on wire " + quoted(net, w) + " (its crossing" + (cs.size() == 1 ? " " : "s ") +
              crossing_list(cs) + "): the wires are held at too few crossings";
  }
  return reason;
}

// The best structure the search found, into r.
void take_found(LayeringResult& r, const Network& net, const Search& s) {
  const int P = static_cast<int>(net.wires.size());
  const int C = static_cast<int>(net.crossings.size());
  r.stable = true;
  r.hooks = s.best_hooks_;
  r.assembly_order = s.best_order_;
  r.steps = s.best_steps_;
  r.max_metric = s.best_.max;
  r.null_crossings = s.best_.nulls;
  r.sum_metric = s.best_.sum;
  r.unbalanced_in_plane = unbalanced_in_plane(net, r.hooks);
  for (int c = 0; c < C; ++c) r.metric[c] = r.hooks[c] == 0 ? 0.0 : s.cost_[c][r.hooks[c] > 0 ? 1 : 0];
  for (int k = 0; k < static_cast<int>(r.steps.size()); ++k)
    if (r.steps[k].size() > (k == 0 ? 2u : 1u)) r.two_hand_steps.push_back(k);
  if (!r.two_hand_steps.empty()) {
    std::vector<std::string> which;
    for (int k : r.two_hand_steps) which.push_back(wire_list(net, r.steps[k]));
    r.warnings.push_back("no order adding one wire at a time is stable; these steps add two wires at once and "
                         "need two hands: " + join(which));
  }
  if (P == 2)
    r.warnings.push_back("a two-wire sculpture can turn about the line where the planes meet; it is judged "
                         "under forces only, like the first pair of any assembly (Sec. 4.2)");
}

// No stable structure: the deepest the search reached and why, into r.
void take_unstable(LayeringResult& r, const Network& net, const Search& s, const LayeringOptions& options,
                   bool tried_pairs) {
  const int C = static_cast<int>(net.crossings.size());
  r.stable = false;
  if (!s.deep_order_.empty()) {
    r.hooks = s.deep_hooks_;
    r.assembly_order = s.deep_order_;
    r.steps = s.deep_steps_;
    for (int c = 0; c < C; ++c) {
      r.metric[c] = r.hooks[c] == 0 ? 0.0 : s.cost_[c][r.hooks[c] > 0 ? 1 : 0];
      r.max_metric = std::max(r.max_metric, r.metric[c]);
      r.sum_metric += r.metric[c];
    }
  }
  // A stopped search proves nothing: it says so, never that no stable assembly exists.
  if (s.stopped()) r.cause = LayeringCause::search_incomplete;
  r.reason = s.stopped() ? "search incomplete: the layering stopped after " + std::to_string(s.nodes_) +
                               " nodes (max_nodes = " + std::to_string(options.max_nodes) +
                               ") before finding a stable assembly; a stable one may exist: raise max_nodes (0: no "
                               "limit) to search further"
                         : explain(net, s, tried_pairs, r.cause);
  r.reason += forbidden_note(options);
  r.forbidden_hooks = forbidden_count(options);
}

}  // namespace

LayeringResult layering(const Network& net, const LayeringOptions& options, const ProgressFn& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  validate(options.contact);
  const int P = static_cast<int>(net.wires.size());
  const int C = static_cast<int>(net.crossings.size());
  check_input(net, options);

  if (options.forbid_too_close) return with_too_close_forbidden(net, options, progress);

  LayeringResult r;
  r.hooks.assign(C, 0);
  r.metric.assign(C, 0.0);
  auto finish = [&]() {
    r.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  };
  report_progress(progress, "layering", 0.0);
  if (P == 1) {
    r.stable = true;
    r.assembly_order = {0};
    r.steps = {{0}};
    r.warnings.push_back("a single wire: there is nothing to layer");
    return finish();
  }
  // A wire sculpture must be connected through crossings.
  r.reason = disconnected(net, r.cause);
  if (!r.reason.empty()) return finish();

  Search s(net, options, progress);
  // Necessary for any answer: the finished sculpture with both hooks' pyramids at every crossing
  // (a superset of the columns of every configuration) must be stable.
  {
    std::vector<int> all(P);
    for (int w = 0; w < P; ++w) all[w] = w;
    const StabilityResult relaxed = s.checker_.check(all, s.relaxed_, P == 2);
    if (!relaxed.stable) {
      std::string detail = what_moves(net, relaxed);  // what moves, or what cannot be balanced, with its advice
      detail += forbidden_note(options);
      r.cause = LayeringCause::mechanism;
      r.forbidden_hooks = forbidden_count(options);
      r.reason = "no hook configuration can make the finished sculpture stable: even with both hook directions "
                 "allowed at every crossing, " + detail;
      r.what_moves = detail.substr(0, detail.find(';'));  // each advice follows a ';' (mechanism_message)
      r.stats.lp_solves = s.checker_.lp_solves();
      return finish();
    }
  }
  s.node_limit_ = options.max_nodes;
  s.run(false);
  bool tried_pairs = false;
  if (!s.found() && !s.stopped() && options.two_wire_steps && P >= 4) {
    tried_pairs = true;
    s.run(true);
  }
  const bool stopped = s.stopped();
  // Key 5 (layering.hpp): a second pass among the structures equal to the best in keys 1-4,
  // seeded with the best (so everything not at least as good in keys 1-4 is pruned at once) and
  // bounded by its own node budget.
  bool in_plane_complete = true;
  if (options.in_plane_tiebreak && s.found() && !stopped) {
    s.best_.unbal = unbalanced_in_plane(net, s.best_hooks_);
    if (s.best_.unbal > 0) {
      s.in_plane_ = true;
      s.node_limit_ = options.in_plane_nodes > 0 ? s.nodes_ + options.in_plane_nodes : 0;
      s.run(tried_pairs);
      in_plane_complete = !s.stopped();
    }
  }
  r.warnings = s.warnings_;
  r.stats.lp_solves = s.checker_.lp_solves();
  r.stats.nodes = s.nodes_;
  r.complete_search = !stopped;
  r.in_plane_complete = in_plane_complete;
  if (!in_plane_complete)
    r.warnings.push_back("the in-plane tie-break (objective key 5) stopped after " +
                         std::to_string(options.in_plane_nodes) + " nodes (in_plane_nodes); " +
                         std::to_string(s.best_.unbal) + " wire" + (s.best_.unbal == 1 ? "" : "s") +
                         " may not balance in plane where another hook pattern of equal cost would");
  if (stopped)
    r.warnings.push_back("the layering search stopped after " + std::to_string(s.nodes_) +
                         " nodes (max_nodes); the result may not be optimal");
  if (s.found())
    take_found(r, net, s);
  else
    take_unstable(r, net, s, options, tried_pairs);
  report_progress(progress, "layering", 1.0);
  return finish();
}

AssemblyCheck check_assembly(const Network& net, const std::vector<int>& hooks,
                             const std::vector<std::vector<int>>& steps, const ContactOptions& contact,
                             const ProgressFn& progress) {
  if (hooks.size() != net.crossings.size())
    throw InputError("check_assembly: " + std::to_string(hooks.size()) + " hooks given for " +
                     std::to_string(net.crossings.size()) + " crossings");
  AssemblyCheck out;
  std::vector<int> prefix;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    report_progress(progress, "check_assembly", static_cast<double>(k) / static_cast<double>(steps.size()));
    prefix.insert(prefix.end(), steps[k].begin(), steps[k].end());
    StabilityOptions check;
    check.forces_only = k == 0 && prefix.size() == 2;  // the first pair: forces only (Sec. 4.2)
    const StabilityResult r = check_stability(net, prefix, hooks, contact, check);
    out.lp_solves += r.lp_solves;
    if (!r.stable) {
      out.failed_step = static_cast<int>(k);
      out.failed_wire = r.failed_wire;
      return out;
    }
  }
  report_progress(progress, "check_assembly", 1.0);
  out.stable = true;
  return out;
}

}  // namespace wiresculpt

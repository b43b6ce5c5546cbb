#pragma once
// In-plane balance of a wire's contact normal forces (beyond the paper; the layering's last
// tie-break, docs/method-layering.md). At a hooked crossing c the normal part of the contact
// force acts along d_c = normalize(n0 × n1), the line common to both planes, so it is in the
// plane of both wires: on wires[0] along -hook·d_c, on wires[1] along +hook·d_c (contact.hpp).
// A wire "balances in plane" when positive normal forces alone, one at each of its hooked
// crossings, can hold it: there are N_c >= 1 (every hooked crossing loaded) with
//   Σ N_c e_c = 0   and   Σ N_c n_w·((x_c − o_w) × e_c) = 0
// (force and torque balance in the wire's plane; e_c the unit direction on this wire, x_c the
// crossing, o_w the plane's origin). When it does not, the force stage can only hold the wire
// with contact forces that leave the planes (friction along the other wire, which is out of this
// wire's plane), the out-of-plane share of docs/method-forces.md §9.
#include <vector>

#include "wiresculpt/network.hpp"

namespace wiresculpt {

/// Whether wire `wire` balances in plane under `hooks` (per crossing, -1/0/1; only the wire's
/// own crossings are read). A wire with no hooked crossing carries no force: true.
bool balances_in_plane(const Network& net, int wire, const std::vector<int>& hooks);

/// The number of wires that do not balance in plane under `hooks`.
int unbalanced_in_plane(const Network& net, const std::vector<int>& hooks);

}  // namespace wiresculpt

#pragma once
/// @file Announcing the departure of participants that were killed.
///
/// A participant that exits in order tells every other one that it leaves (an SPDP "disposed"
/// message), and they drop its readers and writers at once. A killed one says nothing: the others
/// keep sending to it until its discovery lease (3 s) runs out. On shared memory that is worse
/// than wasted: a process killed inside Fast DDS's lock of its own port leaves the lock taken,
/// and every send into that port then waits 1 s for it, with all of the sender's traffic held
/// up behind it (`oscar bench restart` saw healthy modules miss their heartbeats this way).
///
/// So each participant records its GUID prefix in its id claim (a lock file the kernel lets go
/// of when the process dies), and the monitors announce the departure of every participant whose
/// claim nobody holds, in its name, exactly as it would have itself.

#include <string>
#include <vector>

#include "oscar/network.hpp"

namespace oscar {

/// For each participant of `domain` on this machine that died without leaving: sends its
/// departure to the discovery ports of every participant id on the interfaces and peers of
/// `network`, then removes its claim. Returns the GUID prefixes announced.
std::vector<std::string> announce_killed_participants(int domain, const NetworkConfig& network);

}  // namespace oscar

#pragma once
// The PostgreSQL driver of core/sql.h (libpq): one bank shared by many stations and
// transition workers on any hosts. Addressed by a libpq URL, `postgresql://[user@]host[:port]/db`
// (any libpq parameter may follow as `?key=value`, e.g. `options=-csearch_path%3Dstudio2` for a
// second bank in the same database). Results come as text and are converted here: integers and
// doubles exactly (PostgreSQL prints the shortest text that reads back as the same double),
// blobs (bytea) from their hex form.
// SQLSTATE classes become the errors core/sql.h lists: a lost or refused connection (08...,
// 57P0x), a serialization failure or deadlock (40...), a lock not available (55P03): BusyError;
// data corrupted (XX001, XX002): CorruptError; the rest WorkError. A connection that was lost is
// re-established at the start of the next transaction.
#include <string>
#include <string_view>

#include "core/sql.h"

namespace ss::sql {

// True for `postgresql://...` and `postgres://...`: a bank on a PostgreSQL server; anything
// else names a SQLite file.
bool IsPostgresAddress(std::string_view address);

// `address` with its password (in the user part or a `password=` parameter) replaced by "***",
// for logs and error messages.
std::string RedactAddress(const std::string& address);

// Connects (within `connect_timeout` seconds, 10 unless the address sets it). `read_only` makes
// every transaction of the connection read-only. BusyError naming the redacted address when the
// server cannot be reached or refuses the connection.
Db OpenPostgres(const std::string& address, bool read_only);

}  // namespace ss::sql

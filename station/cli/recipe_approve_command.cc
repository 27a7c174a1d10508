// `eol recipe-approve --recipe FILE --by NAME --db DB [--note TEXT] [--out FILE]`: an engineer
// approves a recipe `eol teach` proposed (station/daemon/recipe.h, RecipeApproval). The file gets
// "approval": {"state": "approved", "by", "at", "note"}, is validated, and is written
// atomically (over --recipe unless --out); the approval is appended to the station
// database's recipe audit log (GET /api/recipe/audit) with the proposal's and the approved
// recipe's hashes. While a station holds the database, approve over its API instead
// (POST /api/recipe/approve). Exit: 0 approved, 2 usage, file or database error.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "db/clock.h"
#include "db/store.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/recipe.h"

namespace eol::station::cli {
namespace {

struct ApproveArgs {
  std::string recipe;
  std::string out;
  std::string by;
  std::string note;
  std::string db;
  bool json = false;
};

int RunApprove(const ApproveArgs& a) {
  const Recipe proposal = LoadRecipe(a.recipe);
  if (proposal.Approved())
    throw std::runtime_error(a.recipe + ": not a proposal (" +
                             (proposal.approval ? "approved by " + proposal.approval->by
                                                : std::string("no \"approval\": written by hand")) +
                             "): nothing to approve");
  Recipe approved = proposal;
  approved.approval = RecipeApproval{"approved", a.by, db::UtcNowIso8601(), a.note};
  const nlohmann::json j = RecipeToJson(approved);
  const std::string out = a.out.empty() ? a.recipe : a.out;
  const Recipe checked = ParseRecipe(j, out);  // validated before anything is written
  // The audit entry first: an approval that cannot be recorded is not made.
  const std::unique_ptr<db::Store> store = db::Store::Open(a.db);
  db::RecipeAudit entry;
  entry.at = approved.approval->at;
  entry.who = a.by;
  entry.role = "engineer";
  entry.recipe_id = checked.id;
  entry.old_version = proposal.version;
  entry.new_version = checked.version;
  entry.old_hash = proposal.hash;
  entry.new_hash = checked.hash;
  entry.path = std::filesystem::absolute(out).string();
  store->AppendAudit(entry);
  WriteRecipeFile(out, j);
  if (a.json) {
    std::cout << nlohmann::json{{"id", checked.id},     {"version", checked.version},
                                {"hash", checked.hash}, {"proposal_hash", proposal.hash},
                                {"path", out},          {"by", a.by},
                                {"at", entry.at},       {"db", a.db}}
                     .dump()
              << std::endl;
    return 0;
  }
  std::cout << "approved " << checked.id << " v" << checked.version << " by " << a.by << ": " << out
            << ", sha256 " << checked.hash << " (proposal " << proposal.hash << "); audited in "
            << a.db << "\n";
  return 0;
}

}  // namespace

void AddRecipeApproveCommand(CLI::App& app) {
  auto args = std::make_shared<ApproveArgs>();
  CLI::App* cmd = app.add_subcommand(
      "recipe-approve",
      "Approve a recipe that eol teach proposed: the station refuses to test with a proposal.\n"
      "Writes the approval (who, when, note) into the recipe, validates and writes it\n"
      "atomically, and appends it to the station database's recipe audit log. While the\n"
      "station runs, approve over its API (POST /api/recipe/approve, engineer token).\n"
      "Exit: 0 approved, 2 usage, file or database error.");
  cmd->add_option("--recipe", args->recipe, "The proposed recipe")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--by", args->by, "The approving engineer's name (audit log)")->required();
  cmd->add_option("--db", args->db, "The station database whose audit log records it")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--note", args->note, "Why it is approved (evidence, ticket)");
  cmd->add_option("--out", args->out, "Write the approved recipe here (default: over --recipe)");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("recipe-approve", [&] { return RunApprove(*args); }); });
}

}  // namespace eol::station::cli

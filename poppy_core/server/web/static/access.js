// "Release the motors" beside Stop: every primitive and move stopped, the motors compliant and
// the serial ports closed so that another program (a notebook, `poppy scan`) can open them;
// "Take the motors back" reopens them. A banner says when the ports are released, and when no
// motor answers on a bus ("is the power on?": the robot keeps looking for them).
import { get, post } from "./api.js";
import { every, say } from "./ui.js";

let released = false;

function show(state) {
  released = state.released;
  const button = document.getElementById("release-motors");
  button.textContent = released ? "Take the motors back" : "Release the motors";
  button.title = released
    ? "Reopen the serial ports and drive the motors again (they stay compliant)"
    : "Stop everything, make the motors compliant and close the serial ports so another program can open them";
  button.disabled = false;
  const banner = document.getElementById("access-banner");
  const lines = released
    ? [`Motors released: ${state.ports.join(", ")} free for another program. Take the motors back to drive them again.`]
    : state.no_motors.map((bus) => bus.message);
  banner.textContent = lines.join(" ");
  banner.hidden = lines.length === 0;
}

async function refreshAccess() {
  try { show(await get("/api/v1/motors/access")); } catch { /* the connection badge says */ }
}

async function toggle() {
  const button = document.getElementById("release-motors");
  button.disabled = true;
  try {
    if (released) {
      show(await post("/api/v1/motors/take"));
      say("Motors taken back (compliant)");
    } else {
      const done = await post("/api/v1/motors/release");
      show(done);
      say(`Motors released: ${done.ports.join(", ")} closed`);
    }
  } catch (error) {
    say(`${released ? "Taking the motors back" : "Releasing the motors"} failed: ${error.message}`, true);
    button.disabled = false;
  }
}

document.getElementById("release-motors").addEventListener("click", toggle);
refreshAccess();
every(2, refreshAccess);
